"""The Python module (python/, docs/python.md): tables from bakes and from numpy, their values,
evaluation, sampling and files, and errors that name the argument or field at fault.

Run by ctest (python_test) with PYTHONPATH at the built module; by hand:
  PYTHONPATH=build/python /usr/bin/python3 -m pytest tests/python
The real verify run is slow (a draft: about 20 s) and runs only with WEFT_PYTHON_SLOW=1
(ctest python_verify_test).
"""
import copy
import json
import math
import os
import pathlib

import numpy as np
import pytest

import weft

SOURCE = pathlib.Path(os.environ.get("WEFT_SOURCE_DIR", pathlib.Path(__file__).parents[2]))
# A tiny bake: R = 4 (32 bins per direction), a few thousand photons per band; about a second.
TINY = dict(photons=4000, resolution=4, seed=1)


@pytest.fixture(scope="module")
def spectral():
    return weft.bake_fiber("red-cotton", **TINY)


@pytest.fixture(scope="module")
def rgb():
    return weft.bake_fiber("red-cotton", bands="rgb", **TINY)


def red_cotton_spec():
    return json.loads((SOURCE / "fiber/presets/red-cotton.json").read_text())


def test_baked_table_shape_header_and_values(spectral):
    bins = 2 * 4 * 4  # 2 R^2 (materials/bsdf_table.h)
    assert spectral.values.shape == (bins, bins, 33)
    assert spectral.values.dtype == np.float32
    assert np.all(np.isfinite(spectral.values)) and np.all(spectral.values >= 0)
    assert spectral.values.max() > 0
    assert (spectral.kind, spectral.resolution, spectral.bands) == ("fiber", 4, "390:710:10")
    assert spectral.wavelengths[0] == 390 and spectral.wavelengths[-1] == 710
    assert "spec_hash" in spectral.metadata
    with pytest.raises(ValueError):  # the values are a read-only view of the table's
        spectral.values[0, 0, 0] = 1


def test_an_analytic_surface_lobe_is_named_by_the_table_and_survives_a_file(tmp_path, spectral):
    # bake fiber --surface-lobe analytic: the table names its lobe (docs/fiber-bsdf.md); the
    # cells still hold the whole f, about the sampled table's.
    lobe = weft.bake_fiber("red-cotton", surface_lobe="analytic", **TINY)
    assert spectral.surface_lobe is None
    assert lobe.surface_lobe["surface_lobe"] == "cook-torrance"
    assert len(lobe.surface_lobe["surface_lobe_ior"].split(",")) == 33
    assert abs(lobe.values.sum() / spectral.values.sum() - 1) < 0.1
    lobe.save(tmp_path / "lobe.exr")
    assert weft.load_table(tmp_path / "lobe.exr").surface_lobe == lobe.surface_lobe


def test_a_fabric_table_keeps_its_sheen_through_a_file(tmp_path):
    # bake_fabric(sheen_resolution=...) books the filament's first-surface reflection apart over
    # half vectors (docs/fabric-bsdf.md); the table names it, and a file keeps it.
    fiber = weft.bake_fiber("polyester-filament", bands="rgb", surface_lobe="analytic", photons=400,
                            resolution=2)
    fabric = weft.bake_fabric(fiber, "raytrace", detail="fiber", sheen_resolution=16,
                              sheen_window=4, resolution=2, samples=20)
    # Held over the fibers' Fresnel reflectance at their surface lobe's index (format 6).
    ior = float(fiber.surface_lobe["surface_lobe_ior"].split(",")[0])
    assert fabric.sheen == {"sheen": "half-vector window", "sheen_h_resolution": "16",
                            "sheen_window": "4", "sheen_fresnel_ior": fabric.sheen["sheen_fresnel_ior"]}
    assert abs(float(fabric.sheen["sheen_fresnel_ior"]) - ior) < 1e-12
    fabric.save(tmp_path / "sheen.exr")
    back = weft.load_table(tmp_path / "sheen.exr")
    assert back.sheen == fabric.sheen and back.checksum == fabric.checksum
    with pytest.raises(weft.Error, match="sheen_resolution"):
        weft.bake_fabric(fiber, "raytrace", sheen_resolution=16, resolution=2, samples=20)
    # Light bins twice as fine as the table's (format 7), every reflected exit in the window.
    fine = weft.bake_fabric(fiber, "raytrace", detail="fiber", sheen_resolution=16, sheen_window=4,
                            sheen_light_resolution=4, sheen_light="reflected", resolution=2,
                            samples=20)
    assert fine.sheen["sheen_light_resolution"] == "4"
    assert fine.metadata["sheen_light"] == "reflected"
    fine.save(tmp_path / "fine.exr")
    assert weft.load_table(tmp_path / "fine.exr").sheen == fine.sheen
    with pytest.raises(weft.Error, match="sheen_light_resolution"):
        weft.bake_fabric(fiber, "raytrace", detail="fiber", sheen_resolution=16,
                         sheen_light_resolution=3, resolution=2, samples=20)


def test_same_seed_same_bits_at_any_thread_count():
    a = weft.bake_fiber("red-cotton", bands="rgb", threads=1, **TINY)
    b = weft.bake_fiber("red-cotton", bands="rgb", threads=2, **TINY)
    assert a.checksum == b.checksum


def test_energy_at_most_one_and_red_cotton_looks_red(rgb):
    # total_albedo: the fraction of the light hitting the fiber that leaves it, at most 1
    # (bsdf_table.h TabulatedBsdfTable::total_albedo).
    albedo = rgb.total_albedo()
    assert np.all(albedo > 0) and np.all(albedo <= 1.0)
    assert albedo[0] > albedo[1] and albedo[0] > albedo[2]  # congo red absorbs green and blue
    up = rgb.albedo([0, 0, 1])
    assert np.allclose(up["total"], up["reflectance"] + up["transmittance"])
    assert np.all(up["total"] <= 1.0)


def mirrored_bins(table, axis):
    """The bin of each bin's centre mirrored through the plane axis = 0 (direction_grid.h)."""
    bins = table.values.shape[0]
    out = []
    for k in range(bins):
        c = table.bin_center(k).copy()
        c[axis] = -c[axis]
        out.append(table.bin_of(c))
    assert sorted(out) == list(range(bins))  # the grid is symmetric under the mirror
    return np.array(out)


def test_the_fibers_symmetries_hold_within_noise(rgb):
    # A round fiber looks the same with its axis reversed (x -> -x for both directions) and
    # mirrored through the normal plane at the point (y -> -y): the table changes by no more than
    # between two seeds. (Swapping wi and wo is no symmetry: f at a point of the fiber is not
    # pointwise reciprocal, docs/fiber-bsdf.md; the fiber bake's tests check the reciprocity of
    # the scattering per unit length.)
    other = weft.bake_fiber("red-cotton", bands="rgb", **{**TINY, "seed": 2})
    a, b = rgb.values.astype(np.float64), other.values.astype(np.float64)
    noise = np.linalg.norm(a - b)
    assert noise > 0
    for axis in (0, 1):
        p = mirrored_bins(rgb, axis)
        asymmetry = np.linalg.norm(a - a[p][:, p])
        assert asymmetry < 1.5 * noise, (axis, asymmetry, noise)


def test_eval_at_bin_centres_is_the_stored_cell(spectral):
    for wi_bin, wo_bin in [(0, 5), (3, 20), (17, 30)]:
        wi, wo = spectral.bin_center(wi_bin), spectral.bin_center(wo_bin)
        assert spectral.bin_of(wi) == wi_bin
        np.testing.assert_allclose(spectral.eval(wo, wi), spectral.values[wi_bin, wo_bin],
                                   rtol=1e-6, atol=1e-9)


def test_sample_weight_is_f_cos_over_pdf(rgb):
    # bsdf.h: weight = f(wo, wi) |cos theta_i| / pdf, pdf as pdf() gives it.
    wo = [0.3, 0.2, 0.9]
    drawn = 0
    for u1, u2 in [(0.1, 0.2), (0.5, 0.5), (0.8, 0.3), (0.95, 0.7)]:
        s = rgb.sample(wo, u1, u2)
        if s is None:
            continue
        drawn += 1
        wi = s["wi"]
        assert math.isclose(np.linalg.norm(wi), 1, rel_tol=1e-9)
        assert math.isclose(s["pdf"], rgb.pdf(wo, wi), rel_tol=1e-6)
        np.testing.assert_allclose(s["weight"], rgb.eval(wo, wi) * abs(wi[2]) / s["pdf"],
                                   rtol=1e-5)
    assert drawn > 0


def test_save_load_round_trip_is_bit_exact(spectral, tmp_path):
    path = tmp_path / "fiber.exr"
    spectral.save(path)
    back = weft.load_table(str(path))
    assert np.array_equal(back.values.view(np.uint32), spectral.values.view(np.uint32))
    assert back.metadata == spectral.metadata and back.checksum == spectral.checksum
    with pytest.raises(weft.Error, match="must end in .exr"):
        spectral.save(tmp_path / "fiber.png")


def test_from_array_round_trip_and_checks(rgb):
    t = weft.Table.from_array(np.array(rgb.values), kind="fiber", metadata={"note": "copied"})
    assert np.array_equal(t.values, rgb.values) and t.bands == "rgb"
    assert t.metadata == {"note": "copied"}
    bad = np.array(rgb.values)
    bad[1, 2, 0] = np.nan
    with pytest.raises(weft.Error, match=r"values\[wi 1\]\[wo 2\]\[R\]'.*not finite"):
        weft.Table.from_array(bad)
    bad[1, 2, 0] = -0.5
    with pytest.raises(weft.Error, match=r"values\[wi 1\]\[wo 2\]\[R\]'.*negative"):
        weft.Table.from_array(bad)
    with pytest.raises(weft.Error, match=r"field 'values'.*shape must be \[2R\^2"):
        weft.Table.from_array(np.zeros((4, 4, 3), np.float32))
    with pytest.raises(weft.Error, match=r"field 'values'.*3 \(RGB\) or 33"):
        weft.Table.from_array(np.zeros((2, 2, 5), np.float32))
    with pytest.raises(weft.Error, match=r"field 'bands'"):
        weft.Table.from_array(np.zeros((2, 2, 3), np.float32), bands="390:710:10")
    with pytest.raises(weft.Error, match=r"field 'kind'"):
        weft.Table.from_array(np.zeros((2, 2, 3), np.float32), kind="yarn")


def test_bad_spec_names_the_field():
    spec = red_cotton_spec()
    bad = copy.deepcopy(spec)
    bad["fiber_radius_um"] = -8
    with pytest.raises(weft.Error, match=r"^spec: field 'fiber_radius_um'"):
        weft.bake_fiber(bad, **TINY)
    bad = copy.deepcopy(spec)
    bad["species"][0]["size"]["sigma"] = "wide"
    with pytest.raises(weft.Error, match=r"species\[0\]\.size\.sigma"):
        weft.bake_fiber(bad, **TINY)
    with pytest.raises(weft.Error, match="no-such-preset"):
        weft.bake_fiber("no-such-preset", **TINY)
    with pytest.raises(weft.Error, match=r"field 'resolution'"):
        weft.bake_fiber("red-cotton", photons=10, resolution=1)
    with pytest.raises(weft.Error, match=r"field 'bands'"):
        weft.bake_fiber("red-cotton", bands="hyperspectral", **TINY)


def test_a_spec_dict_bakes_like_its_preset():
    by_dict = weft.bake_fiber(red_cotton_spec(), bands="rgb", **TINY)
    by_name = weft.bake_fiber("red-cotton", bands="rgb", **TINY)
    assert by_dict.metadata["spec_hash"] == by_name.metadata["spec_hash"]
    assert by_dict.checksum == by_name.checksum


def test_quiet_by_default_progress_on_request(capfd):
    weft.bake_fiber("red-cotton", bands="rgb", **TINY)
    quiet = capfd.readouterr()
    assert quiet.out == "" and quiet.err == ""
    weft.bake_fiber("red-cotton", bands="rgb", progress=True, **TINY)
    err = capfd.readouterr().err
    assert "100.0%" in err, err  # a stage's end always prints (core/progress.h)


def test_long_work_needs_yes_long():
    # 2^40 photons per band x 33 bands at 2.1 us per photon per core with the bake's defaults
    # (fiber_table_bake.h fiber_bake_min_seconds_per_photon) is years on any machine: refused
    # before any work.
    with pytest.raises(weft.Error, match=r"field 'photons'.*pass yes_long=True"):
        weft.bake_fiber("red-cotton", photons=2**40, resolution=4)


def test_bake_fabric_by_the_papers_summation(rgb):
    fabric = weft.bake_fabric(rgb, "summation", resolution=4, samples=2)
    assert fabric.kind == "fabric" and fabric.values.shape == (32, 32, 3)
    assert np.all(np.isfinite(fabric.values)) and fabric.values.max() > 0
    assert "sample" in fabric.metadata
    # The paper's sum sends nothing below the cloth for light from above
    # (fabric_summation.h, kPaper): rows of upper wi bins, columns of lower wo bins, are zero.
    upper = 4 * 4  # the first R^2 bins are the upper hemisphere (direction_grid.h)
    assert np.all(fabric.values[:upper, upper:] == 0)
    with pytest.raises(weft.Error, match=r"field 'method'"):
        weft.bake_fabric(rgb, "guess", resolution=4)
    with pytest.raises(weft.Error, match=r"field 'samples'"):
        weft.bake_fabric(rgb, "summation", resolution=4, samples=5000)


# The ray trace at its smallest: R = 2, a few particles per incident bin; well under a second.
TINY_TRACE = dict(resolution=2, samples=40, seed=1)


def test_bake_fabric_per_yarn_fibers(rgb, tmp_path):
    same, white = tmp_path / "same.exr", tmp_path / "white.exr"
    rgb.save(same)
    weft.bake_fiber("white-cotton", bands="rgb", **TINY).save(white)
    single = weft.bake_fabric(rgb, "raytrace", **TINY_TRACE)
    # One table on every yarn traces as the single-fiber call, bit for bit (fabric_raytrace.h).
    warp_same = weft.bake_fabric(rgb, "raytrace", warp_fiber=str(same), **TINY_TRACE)
    assert np.array_equal(warp_same.values, single.values)
    two = weft.bake_fabric(rgb, "raytrace", weft_fiber=str(white), **TINY_TRACE)
    assert two.values.shape == single.values.shape and not np.array_equal(two.values,
                                                                         single.values)
    with pytest.raises(weft.Error, match=r"field 'warp_fiber'.*method raytrace"):
        weft.bake_fabric(rgb, "summation", warp_fiber=str(white), resolution=2)
    with pytest.raises(weft.Error, match=r"field 'thread_colours'.*WIF draft"):
        weft.bake_fabric("white-cotton", "raytrace", thread_colours=True, **TINY_TRACE)


def test_bake_fiber_colour_is_refused_where_it_cannot_be_matched():
    # The match bakes the spec by name through a cloth (fabric/fiber_colour.h): a dict cannot be,
    # and a cloth without a colour to read is a mistake, both said before any work.
    with pytest.raises(weft.Error, match=r"field 'colour'.*give the spec as a file"):
        weft.bake_fiber(red_cotton_spec(), colour="lab:40,20,10", **TINY)
    with pytest.raises(weft.Error, match=r"field 'colour_weave'"):
        weft.bake_fiber("red-cotton", colour_weave="weave.json", **TINY)


def test_bake_fabric_weave_table(rgb, tmp_path):
    out = tmp_path / "weave.exr"
    fabric = weft.bake_fabric(rgb, "raytrace", weave_out=out, weave_positions="2x3",
                              weave_resolution=1, **TINY_TRACE)
    assert fabric.kind == "fabric" and out.stat().st_size > 0
    with pytest.raises(weft.Error, match=r"field 'weave_positions'.*need weave_out"):
        weft.bake_fabric(rgb, "raytrace", weave_positions=2, **TINY_TRACE)
    with pytest.raises(weft.Error, match=r"field 'weave_out'.*\.exr"):
        weft.bake_fabric(rgb, "raytrace", weave_out=tmp_path / "w.png", **TINY_TRACE)
    with pytest.raises(weft.Error, match=r"field 'estimator'.*method raytrace"):
        weft.bake_fabric(rgb, "summation", estimator="nee", resolution=2)


def test_verify_checks_its_arguments_first(tmp_path):
    with pytest.raises(weft.Error, match="quality"):
        weft.verify("bogus", output=tmp_path / "out")
    with pytest.raises(weft.Error, match=r"pattern|wif"):
        weft.verify("draft", output=tmp_path / "out", pattern="plain", wif="x.wif")


@pytest.mark.skipif(os.environ.get("WEFT_PYTHON_SLOW") != "1",
                    reason="a draft verify (about 20 s): WEFT_PYTHON_SLOW=1")
def test_verify_draft_writes_its_report(tmp_path):
    out = tmp_path / "report"
    metrics = weft.verify("draft", output=out, plots=False)
    assert metrics["report_folder"] == str(out)
    on_disk = json.loads((out / "metrics.json").read_text())
    assert {k: v for k, v in metrics.items() if k != "report_folder"} == on_disk
    assert (out / "inplane.csv").stat().st_size > 0
