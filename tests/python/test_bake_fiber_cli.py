"""weft.bake_fiber and `weft bake fiber` bind one request (fiber/fiber_bake_request.h): every
option of the command but those that only a command line has exists in Python and back, and
both, given the same photons and nothing else, bake the same table (so their defaults agree).

Run by ctest (python_cli_test) with WEFT_BINARY at the built weft; by hand:
  WEFT_BINARY=build/tools/weft PYTHONPATH=build/python /usr/bin/python3 -m pytest tests/python
"""
import os
import pathlib
import re
import subprocess

import numpy as np
import pytest

import weft

SOURCE = pathlib.Path(os.environ.get("WEFT_SOURCE_DIR", pathlib.Path(__file__).parents[2]))
WEFT = pathlib.Path(os.environ.get("WEFT_BINARY", SOURCE / "build/tools/weft"))

# Options only a command line has: where the table goes, sharding and checkpoints, the printout.
CLI_ONLY = {"help", "output", "shard", "resume", "json", "quiet"}
# Python's counterparts of weft's global --yes-long and of --quiet (Python is quiet by default).
PYTHON_ONLY = {"yes_long", "progress"}


def cli_options():
    """Option name (Python's spelling) -> the help line, from `weft bake fiber --help`."""
    if not WEFT.exists():
        pytest.skip(f"no weft binary at {WEFT} (set WEFT_BINARY)")
    text = subprocess.run([WEFT, "bake", "fiber", "--help"], check=True, capture_output=True,
                          text=True).stdout
    options, name = {}, None
    for line in text.splitlines():
        # "  --name TYPE ..." or "  -o,--output ..." or "  --mirror-fold,--no-mirror-fold{false}",
        # the description on the same line or on the deeper-indented lines after it.
        m = re.match(r"\s+(?:-\w,)?--([\w-]+)", line)
        if m:
            name = m.group(1).replace("-", "_")
            options[name] = line
        elif name and line.startswith("    "):
            options[name] += line
    positionals = re.search(r"Positionals:\n((?:[ \t]+\S.*\n)+)", text).group(1)
    for line in positionals.splitlines():
        options[line.split()[0]] = line
    return options


def python_parameters():
    """Parameter -> its default text (None when required), from bake_fiber's signature."""
    signature = weft.bake_fiber.__doc__.splitlines()[0]
    inside = signature[signature.index("(") + 1:signature.rindex(") ->")]
    params = {}
    for part in re.split(r",\s*", inside):
        if part == "*":
            continue
        name, _, default = part.partition(" = ")
        params[name.split(":")[0]] = default or None
    return params


def test_every_cli_option_is_a_python_argument_and_back():
    cli = set(cli_options()) - CLI_ONLY
    python = set(python_parameters()) - PYTHON_ONLY
    assert cli == python, f"only in the CLI: {cli - python}; only in Python: {python - cli}"


def test_options_the_spec_and_route_decide_default_to_none():
    # The command's help says their default depends on the spec and route; Python says None.
    params = python_parameters()
    for name in ("estimator", "surface_samples", "entry"):
        assert params[name] == "None", name
    assert "default on" in cli_options()["mirror_fold"] and params["mirror_fold"] == "True"


def test_cli_and_python_defaults_bake_the_same_table(tmp_path):
    # Only photons (the cost) and threads (no effect on the bits) given: every other option at
    # each front end's default, so equal tables mean equal defaults (the header names them).
    out = tmp_path / "cli.exr"
    subprocess.run([WEFT, "bake", "fiber", "red-cotton", "--photons", "200", "--threads", "2",
                    "-o", out, "--quiet"], check=True, capture_output=True)
    cli = weft.load_table(out)
    python = weft.bake_fiber("red-cotton", photons=200, threads=2)
    ignore = {"program_version"}
    assert {k: v for k, v in cli.metadata.items() if k not in ignore} == \
        {k: v for k, v in python.metadata.items() if k not in ignore}
    assert cli.resolution == python.resolution and cli.bands == python.bands
    assert np.array_equal(cli.values, python.values)


def test_python_refuses_what_the_plan_refuses():
    with pytest.raises(weft.Error, match=r"field 'surface_samples': must be in \[1, 1024\]"):
        weft.bake_fiber("red-cotton", photons=10, resolution=2, surface_samples=0)
    with pytest.raises(weft.Error, match=r"field 'estimator': must be 'plain' or 'nee'"):
        weft.bake_fiber("red-cotton", photons=10, resolution=2, estimator="mis")
    with pytest.raises(weft.Error, match=r"field 'estimator'.*direct route"):
        weft.bake_fiber("red-cotton", photons=10, resolution=2, route="bssrdf", estimator="nee")
