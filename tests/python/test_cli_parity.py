"""The Python module and the command line bind one request per command (fiber/fiber_bake_request.h,
fabric/fabric_bake.h, verify/plan.h, exchange/view_request.h): every option of `weft bake fiber`,
`weft bake fabric`, `weft verify` and `weft view` but those only a command line has exists as a
keyword of weft.bake_fiber, weft.bake_fabric, weft.verify and weft.view and back, with the
default the command's help states; the fiber bake's help states none, so both front ends bake
with their defaults and must give the same table.

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

# Python's counterparts of weft's global --yes-long and of --quiet (Python is quiet by default).
PYTHON_ONLY = {"yes_long", "progress"}


def cli_options(*command):
    """Option name (Python's spelling) -> (its help text, the default the help states or None),
    from `weft COMMAND --help`; positionals too."""
    if not WEFT.exists():
        pytest.skip(f"no weft binary at {WEFT} (set WEFT_BINARY)")
    text = subprocess.run([WEFT, *command, "--help"], check=True, capture_output=True,
                          text=True).stdout
    options, name = {}, None
    for line in text.splitlines():
        # "  --name TYPE=DEFAULT  help", "  -o,--output ...", "  --mirror-fold,--no-mirror-fold",
        # the description on the same line or on the deeper-indented lines after it.
        m = re.match(r"\s+(?:-\w,)?--([\w-]+)", line)
        if m:
            name = m.group(1).replace("-", "_")
            column = re.split(r"\s{2,}", line.strip())[0]
            default = re.search(r"=(\S+)$", column)
            options[name] = [line, default.group(1) if default else None]
        elif name and line.startswith("    "):
            options[name][0] += line
    positionals = re.search(r"Positionals:\n((?:[ \t]+\S.*\n)+)", text)
    for line in positionals.group(1).splitlines() if positionals else []:
        options[line.split()[0]] = [line, None]
    return options


def split_top_level(text):
    """'a: int = 1, b: list = [1, 2], c: str = 'x,y'' -> its parameters, commas inside brackets
    and quotes kept."""
    parts, depth, start, quoted = [], 0, 0, False
    for i, ch in enumerate(text):
        if ch == "'":
            quoted = not quoted
        elif quoted:
            continue
        elif ch in "[(":
            depth += 1
        elif ch in "])":
            depth -= 1
        elif ch == "," and depth == 0:
            parts.append(text[start:i].strip())
            start = i + 1
    return parts + [text[start:].strip()]


def python_parameters(function):
    """Parameter -> its default as pybind11's signature writes it (None when required)."""
    signature = function.__doc__.splitlines()[0]
    inside = signature[signature.index("(") + 1:signature.rindex(") ->")]
    params = {}
    for part in split_top_level(inside):
        if part == "*":
            continue
        name, _, default = part.partition(" = ")
        params[name.split(":")[0]] = default.strip("'") if default else None
    return params


def check_both_ways(command, function, cli_only, python_only=PYTHON_ONLY, renamed=None,
                    default_in_words=None):
    """Every option of the command but 'cli_only' is a parameter of 'function' (under its Python
    name, 'renamed') and back, but 'python_only'; where the help states a default (or says it in
    words: 'default_in_words'), Python's is the same; where it states none, Python's says
    'not given' (None or False), unless the option is in 'default_in_words'."""
    renamed, default_in_words = renamed or {}, default_in_words or {}
    cli = {renamed.get(n, n): d for n, (_, d) in cli_options(*command).items() if n not in cli_only}
    python = python_parameters(function)
    assert set(cli) == set(python) - python_only, \
        f"only in the CLI: {set(cli) - set(python)}; only in Python: {set(python) - set(cli)}"
    for name, default in cli.items():
        if default is not None:
            assert python[name] == default, name
        elif name in default_in_words:
            assert python[name] == default_in_words[name], name
        else:
            assert python[name] in ("None", "False", None), name


def test_bake_fiber_takes_the_commands_options():
    cli = set(cli_options("bake", "fiber")) - {"help", "output", "shard", "resume", "json",
                                                 "quiet"}
    python = set(python_parameters(weft.bake_fiber)) - PYTHON_ONLY
    assert cli == python, f"only in the CLI: {cli - python}; only in Python: {python - cli}"


def test_bake_fiber_options_the_spec_and_route_decide_default_to_none():
    # The command's help says their default depends on the spec and route; Python says None.
    params = python_parameters(weft.bake_fiber)
    for name in ("estimator", "surface_samples", "entry"):
        assert params[name] == "None", name
    assert "default on" in cli_options("bake", "fiber")["mirror_fold"][0]
    assert params["mirror_fold"] == "True"


def test_bake_fiber_defaults_bake_the_same_table(tmp_path):
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


def test_bake_fiber_refuses_what_the_plan_refuses():
    with pytest.raises(weft.Error, match=r"field 'surface_samples': must be in \[1, 1024\]"):
        weft.bake_fiber("red-cotton", photons=10, resolution=2, surface_samples=0)
    with pytest.raises(weft.Error, match=r"field 'estimator': must be 'plain' or 'nee'"):
        weft.bake_fiber("red-cotton", photons=10, resolution=2, estimator="mis")
    with pytest.raises(weft.Error, match=r"field 'estimator'.*direct route"):
        weft.bake_fiber("red-cotton", photons=10, resolution=2, route="bssrdf", estimator="nee")


def test_bake_fabric_takes_the_commands_options_and_defaults():
    check_both_ways(("bake", "fabric"), weft.bake_fabric,
                    cli_only={"help", "output", "shard", "resume", "json", "quiet"},
                    renamed={"weave": "sample"}, default_in_words={"threads": "0"})


def test_verify_takes_the_commands_options_and_defaults():
    # The suite is the command's (a report per fabric and a page); Python runs one verify.
    check_both_ways(("verify",), weft.verify,
                    cli_only={"help", "shard", "json", "quiet", "suite", "suite_file"},
                    python_only=PYTHON_ONLY | {"plots"},
                    default_in_words={"threads": "0"})


def test_the_check_fails_when_a_front_end_lacks_an_option():
    # The walk itself can fail: a command with an option Python lacks is caught.
    with pytest.raises(AssertionError, match="only in the CLI"):
        check_both_ways(("bake", "fabric"), weft.bake_fiber, cli_only={"help"})


def test_view_takes_the_commands_options(tmp_path):
    # weft.view is `weft view` without --json (Python returns the report); a page it writes holds
    # the in-plane curves of the table.
    check_both_ways(("view",), weft.view, cli_only={"help", "json"}, python_only=set())
    fiber = weft.bake_fiber("white-cotton", photons=2000, resolution=4, bands="rgb")
    fiber.save(tmp_path / "fiber.exr")
    report = weft.view(tmp_path / "fiber.exr", tmp_path / "page.html", name="white cotton")
    page = (tmp_path / "page.html").read_text()
    assert page.lower().startswith("<!doctype html>") and "white cotton" in page
    assert report["format"] and isinstance(report["figures"], dict)
    with pytest.raises(weft.Error, match="output"):
        weft.view(tmp_path / "fiber.exr", tmp_path / "page.txt")
