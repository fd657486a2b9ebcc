"""The Python module against the library's own ground truth: analytic materials written as measurements,
fitted, baked, evaluated, sampled, rendered and compared (docs/python.md)."""
import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest

import facetfit

GOLD = "builtin:gold-ggx-0.15"  # analytic GGX, alpha 0.15 (model/builtin.cpp)
RGL_DIR = os.path.join(os.path.dirname(__file__), "..", "..", "..", "shared", "data", "rgl")


def directions(n, seed, upper=True):
    """n unit vectors, uniform over the upper hemisphere (or the whole sphere)."""
    rng = np.random.default_rng(seed)
    v = rng.normal(size=(n, 3))
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    if upper:
        v[:, 2] = np.abs(v[:, 2])
    return v


@pytest.fixture(scope="module")
def gold_fit():
    return facetfit.fit(GOLD)


def test_version_and_builtins():
    assert facetfit.__version__
    assert "gold-ggx-0.15" in facetfit.builtins()


def test_fit_recovers_the_analytic_alpha(gold_fit):
    f = gold_fit
    assert f.ok and f.problem == ""
    assert f.alpha_ggx == pytest.approx(0.15, rel=0.03)
    assert f.theta.shape == f.ndf.shape == f.sigma.shape == (91,)
    assert f.fresnel.shape == (90, 3) and facetfit.Fit.fresnel_theta_d.shape == (90,)
    # D is normalised: the integral of D cos over the hemisphere is one.
    t = np.linspace(0.0, math.pi / 2, 20001)
    d = f.D(t)
    y = d * np.cos(t) * np.sin(t)
    assert 0.5 * np.sum((y[1:] + y[:-1]) * np.diff(t)) * 2 * math.pi == pytest.approx(1.0, abs=0.01)
    assert np.allclose(f.slope_pdf(t), d * np.cos(t) ** 4)
    record = f.record
    assert record["source"] == GOLD and record["ggx"]["alpha"] == pytest.approx(0.15, rel=0.03)
    json.dumps(record)  # plain JSON types


def test_paper_fit_is_the_power_iteration_alone():
    f = facetfit.fit(facetfit.load(GOLD), refine="none")
    assert f.ok and f.iterations > 0
    assert np.allclose(f.ndf, f.ndf_extraction)


def test_recommended_agrees_with_the_record_and_the_lut(tmp_path):
    # fit/recommend.h: the same representation and parameters from Fit, its record, and the baked LUT.
    f = facetfit.fit("builtin:red-plastic")
    rec = f.recommended()
    assert rec == f.record["recommended"]
    # The tabulated lobe is nearest (0.002 from the measurement), the closures (0.0048) beyond 0.2 / 116 of it,
    # the F82 GGX fit far beyond (0.028): the tabulated lobe. A tolerance of 2 takes the closures, 20 the GGX fit.
    assert rec["representation"] == "tabulated" and rec["alpha"] is None
    assert rec["error"] == pytest.approx(f.record["error"])
    closures = f.recommended(tolerance=2.0)
    assert closures["representation"] == "closures" and closures["alpha"] is None
    assert closures["error"] == pytest.approx(f.record["closures"]["error"])
    cheap = f.recommended(tolerance=20.0)
    assert cheap["representation"] == "ggx" and cheap["alpha"] == pytest.approx(f.record["ggx"]["alpha"])
    assert cheap["alpha"] != pytest.approx(f.alpha_ggx, rel=1e-3)  # the moment estimate is not the fit
    f.write_lut(tmp_path / "red.exr")
    lut = facetfit.read_lut(tmp_path / "red.exr")
    assert lut.representation == rec["representation"] == lut.recommended["representation"]
    assert lut.recommended["alpha"] is None  # the tabulated lobe's NDF is a table
    assert lut.recommended["error"] == pytest.approx(rec["error"], rel=1e-6)
    for key in ("f0", "f82", "body"):
        assert lut.recommended[key] == pytest.approx(rec[key], rel=1e-6, abs=1e-7)
    assert f.recommended(tolerance=0.0)["representation"] == "tabulated"
    # Every representation's distance (fit/representations.h), the record's and, as floats, the LUT's.
    assert list(f.distances) == ["tabulated", "ggx", "beckmann", "lsq", "closures"]
    assert f.distances["tabulated"] == f.error and f.distances["closures"] == f.record["closures"]["error"]
    for name in ("ggx", "beckmann", "lsq"):
        assert f.distances[name] == f.record[name]["error"]
    assert lut.distances == pytest.approx(f.distances, rel=1e-6)
    assert facetfit.fit("builtin:black-glossy-ggx-0.08").recommended()["alpha"] is None


def test_fit_model_matches_the_measurement(gold_fit):
    m = facetfit.load(GOLD)
    model = gold_fit.model()
    o, i = directions(4000, 1), directions(4000, 2)
    keep = (o[:, 2] > 0.2) & (i[:, 2] > 0.2)
    measured, fitted = m.eval(o[keep], i[keep]), model.eval(o[keep], i[keep])
    assert measured.shape == fitted.shape == (keep.sum(), 3)
    # Relative error of f cos_i, summed: the fit holds the analytic material within a few percent.
    w = i[keep, 2:3]
    ok = np.isfinite(measured).all(axis=1)
    assert np.abs((fitted - measured) * w)[ok].sum() / np.abs(measured * w)[ok].sum() < 0.05


def test_eval_broadcasts_and_checks_shapes():
    model = facetfit.material({"type": "ggx", "alpha": 0.3, "f0": [0.9, 0.6, 0.3]})
    o = np.array([0.0, 0.0, 1.0])
    i = directions(10, 3)
    assert model.eval(o, i).shape == (10, 3)
    assert model.eval(i.reshape(2, 5, 3), i.reshape(2, 5, 3)).shape == (2, 5, 3)
    assert np.allclose(model.eval(o, i)[4], model.eval(o, i[4]))
    with pytest.raises(ValueError, match="3-vectors"):
        model.eval(o, np.zeros((4, 2)))
    with pytest.raises(ValueError, match="same shape"):
        model.eval(directions(3, 1), directions(4, 2))


def test_directions_are_o_then_i_on_a_nonreciprocal_measurement():
    """RGL files are not reciprocal: swapping the arguments of eval changes the answer, and the model
    of a measured material must take o (the viewer) first, as the renderer and Mitsuba 3 do."""
    path = os.path.join(RGL_DIR, "cc_ibiza_sunset_rgb.bsdf")
    if not os.path.exists(path):
        pytest.skip("shared RGL data absent (../shared/data/rgl)")
    view = facetfit.material({"type": "measured", "file": path, "slices": "view"})
    light = facetfit.material({"type": "measured", "file": path, "slices": "light"})
    o, i = directions(2000, 4), directions(2000, 5)
    a, b = view.eval(o, i), light.eval(i, o)
    assert np.allclose(a, b, rtol=1e-9, atol=1e-12)  # light slices picked by i == view slices with o, i swapped
    assert not np.allclose(view.eval(o, i), view.eval(i, o), rtol=1e-3)


def test_sample_agrees_with_pdf_and_eval():
    model = facetfit.material({"type": "ggx", "alpha": 0.2, "f0": [1, 1, 1]})
    n = 200000
    o = np.array([math.sin(0.6), 0.0, math.cos(0.6)])
    u = np.random.default_rng(7).random((n, 3))
    s = model.sample(o, u)
    ok = s["pdf"] > 0
    assert ok.mean() > 0.9
    i = s["i"][ok]
    assert np.allclose(np.linalg.norm(i, axis=1), 1.0)
    assert np.allclose(s["pdf"][ok], model.pdf(o, i), rtol=1e-6)
    assert np.allclose(s["weight"][ok], model.eval(o, i) * i[:, 2:3] / s["pdf"][ok, None], rtol=1e-6)
    # The mean weight estimates the directional albedo: against a uniform-hemisphere estimate.
    v = directions(n, 8)
    uniform = (model.eval(o, v) * v[:, 2:3]).mean(axis=0) * 2 * math.pi
    sampled = s["weight"].sum(axis=0) / n
    assert np.allclose(sampled, uniform, rtol=0.03)


def test_lut_round_trip(tmp_path, gold_fit):
    path = str(tmp_path / "gold.exr")
    gold_fit.write_lut(path)
    lut = facetfit.read_lut(path)
    assert lut.source == GOLD and lut.alpha_ggx == pytest.approx(gold_fit.alpha_ggx)
    assert np.allclose(lut.ndf, gold_fit.ndf, rtol=1e-5)  # stored as float32
    o, i = directions(500, 9), directions(500, 10)
    assert np.allclose(lut.model().eval(o, i), gold_fit.model().eval(o, i), rtol=1e-4, atol=1e-6)
    ggx = lut.parametric("ggx").eval(o, i)
    assert ggx.shape == (500, 3)
    with pytest.raises(ValueError):
        lut.parametric("phong")
    with pytest.raises(facetfit.Error, match="nope.exr"):
        facetfit.read_lut(str(tmp_path / "nope.exr"))


def test_closures_in_fit_lut_and_record(tmp_path, gold_fit):
    # The closure representation, what the production OSL material renders, the same in the fit, its record
    # and the LUT; its model evaluates it.
    c = gold_fit.closures
    assert c == gold_fit.record["closures"]
    assert 1 <= len(c["lobes"]) <= 3 and c["lobes"][0]["family"] == "ggx"
    path = str(tmp_path / "gold.exr")
    gold_fit.write_lut(path)
    lut = facetfit.read_lut(path)
    assert len(lut.closures["lobes"]) == len(c["lobes"])
    assert lut.closures["lobes"][0]["alpha_x"] == pytest.approx(c["lobes"][0]["alpha_x"], rel=1e-6)
    o, i = directions(500, 11), directions(500, 12)
    assert np.allclose(lut.closures_model().eval(o, i), gold_fit.closures_model().eval(o, i), rtol=1e-4, atol=1e-6)
    # Gold is one GGX lobe with a conductor's Fresnel: its closures reflect what its tabulated lobe does over
    # these pairs, within 1% (0.1% when written; pair by pair they part near the peak, where the F82 and
    # generalized-Schlick lobes share out the conductor's Fresnel curve).
    reflected = lambda model: (model.eval(o, i) * i[:, 2:3]).sum(axis=0)
    assert np.allclose(reflected(lut.closures_model()), reflected(lut.model()), rtol=0.01)
    # As MaterialX: MaterialX's own validation accepts the document.
    mx = pytest.importorskip("MaterialX")
    doc, stdlib = mx.createDocument(), mx.createDocument()
    mx.loadLibraries(mx.getDefaultDataLibraryFolders(), mx.getDefaultDataSearchPath(), stdlib)
    mx.readFromXmlString(doc, lut.materialx("gold 0.15"))
    doc.importLibrary(stdlib)
    assert doc.validate()[0] and [m.getName() for m in doc.getMaterialNodes()] == ["gold_0_15"]


def test_hostile_directions_raise_value_error(tmp_path, gold_fit):
    """Issue 47: NaN, infinite, huge, denormal and None directions crashed the LUT, MERL and RGL models;
    each is a ValueError naming the argument and the index, before any model sees it."""
    path = str(tmp_path / "gold.exr")
    gold_fit.write_lut(path)
    models = [gold_fit.model(), facetfit.read_lut(path).model(), facetfit.material({"type": "measured", "file": GOLD})]
    rgl = os.path.join(RGL_DIR, "paper_white_rgb.bsdf")
    if os.path.exists(rgl):
        models.append(facetfit.material({"type": "measured", "file": rgl, "proposal": path}))
    good = np.array([0.0, 0.0, 1.0])
    bad = [np.array([np.nan] * 3), np.array([0.0, np.inf, 1.0]), np.array([0.0, 0.0, 1e300]),
           np.array([1e-310, 0.0, 0.0]), np.array([None, None, None], dtype=object), np.zeros(3)]
    for model in models:
        for b in bad:
            for call in (lambda: model.eval(good, b), lambda: model.eval(b, good), lambda: model.pdf(good, b),
                         lambda: model.sample(b, np.array([0.5, 0.5, 0.5]))):
                with pytest.raises(ValueError, match=r"\[0\]: must be a finite unit vector"):
                    call()
        with pytest.raises(ValueError, match=r"u\[1\]: must be three numbers in \[0, 1\]"):
            model.sample(good, np.array([[0.5, 0.5, 0.5], [0.5, np.nan, 0.5]]))
    with pytest.raises(ValueError, match="finite unit vector"):
        facetfit.load(GOLD).eval(good, np.array([np.nan] * 3))
    # A direction within float32's rounding of unit length is taken.
    assert np.isfinite(models[0].eval(good, np.array([0.6, 0.0, 0.8], dtype=np.float32))).all()


def test_schlick_only_closures(tmp_path):
    """closure_fresnel='schlick': every lobe a generalized Schlick (what MaterialX's OSL renders exactly)."""
    record = facetfit.bake(GOLD, str(tmp_path), closure_fresnel="schlick")
    lut = facetfit.read_lut(str(tmp_path / "gold-ggx-0.15.exr"))
    assert record["status"] == "baked" and all(l["fresnel"] == "schlick" for l in lut.closures["lobes"])
    assert lut.materialx("gold", color82=True) == lut.materialx("gold")  # nothing for color82 to keep
    with pytest.raises(ValueError, match="closure_fresnel"):
        facetfit.fit(GOLD, closure_fresnel="f83")


def test_bake_caches(tmp_path):
    first = facetfit.bake(GOLD, str(tmp_path), refine="none")
    again = facetfit.bake(GOLD, str(tmp_path), refine="none")
    assert first["status"] == "baked" and again["status"] == "cached"
    assert os.path.exists(tmp_path / "gold-ggx-0.15.exr")


def test_bake_in_a_working_space(tmp_path):
    """Issue 48: bake(working_space=...) as bake --working-space: the LUT records its space and holds its
    colours converted (the Rec.709 to ACEScg matrix of the ACES config); a space without a config raises."""
    ocio = pytest.importorskip("PyOpenColorIO")
    config = tmp_path / "aces.ocio"
    config.write_text(ocio.Config.CreateFromBuiltinConfig("cg-config-v1.0.0_aces-v1.3_ocio-v2.1").serialize())
    facetfit.bake(GOLD, str(tmp_path / "a"), refine="none")
    rec709 = facetfit.read_lut(tmp_path / "a" / "gold-ggx-0.15.exr")
    facetfit.bake(GOLD, str(tmp_path / "b"), refine="none", working_space="ACEScg", ocio_config=str(config))
    acescg = facetfit.read_lut(tmp_path / "b" / "gold-ggx-0.15.exr")
    assert rec709.colorspace == "lin_rec709" and acescg.colorspace == "ACEScg"
    to_acescg = np.array([[0.6130974293, 0.3395231366, 0.0473794527], [0.0701937228, 0.9163538814, 0.0134523986],
                          [0.0206155926, 0.1095697731, 0.8698146343]])
    assert np.allclose(acescg.fresnel, rec709.fresnel @ to_acescg.T, atol=1e-5)
    with pytest.raises(facetfit.Error, match="needs an OpenColorIO config"):
        facetfit.bake(GOLD, str(tmp_path / "c"), working_space="ACEScg")


def test_bake_takes_what_the_command_takes(tmp_path):
    """Issue 48: a folder (the command bakes it; Python said it held no supported file) and a missing output
    folder (created, not 'cannot lock'); a batch goes on past a bad file."""
    src = tmp_path / "src"
    src.mkdir()
    (src / "bad.binary").write_bytes(b"\x01")
    rgl = os.path.join(RGL_DIR, "paper_white_rgb.bsdf")
    if os.path.exists(rgl):
        os.symlink(rgl, src / "paper.bsdf")
    records = facetfit.bake(str(src), str(tmp_path / "new" / "luts"), refine="none")
    assert records[0]["status"] == "failed" and "bad.binary" in records[0]["error"]
    if os.path.exists(rgl):
        assert records[1]["status"] == "baked" and (tmp_path / "new" / "luts" / "paper.exr").exists()
    with pytest.raises(ValueError, match="name"):
        facetfit.bake(str(src), str(tmp_path / "x"), name="one")
    records = facetfit.bake("builtin:", str(tmp_path / "all"), refine="none", sampling=False)
    assert len(records) == len(facetfit.builtins()) and all(r["status"] == "baked" for r in records)


def test_the_wheel_installs_the_command(tmp_path):
    """Issue 48: `pip install .` puts the command among the environment's scripts and its plugins in the
    environment's lib/facetfit, where it looks for them: it bakes, reads back what Python wrote, and writes
    a PNG through the OpenImageIO module."""
    command = os.path.join(os.path.dirname(sys.executable), "facetfit")
    run = lambda *args: subprocess.run([command, *args], capture_output=True, text=True, check=True).stdout
    assert run("--version").startswith("facetfit " + facetfit.__version__ + " (")
    f = facetfit.fit("builtin:red-plastic")
    f.write_lut(tmp_path / "red.exr")
    info = json.loads(run("info", "--json", str(tmp_path / "red.exr")))
    assert info["metadata"]["recommended"]["representation"] == f.recommended()["representation"]
    run("render", "--material", str(tmp_path / "red.exr"), "--spp", "1", "--width", "16", "--height", "12",
        "-o", str(tmp_path / "red-render.exr"), "--png", str(tmp_path / "red-render.png"))
    assert (tmp_path / "red-render.png").stat().st_size > 0


def test_write_image(tmp_path):
    image = facetfit.render({"camera": {"width": 16, "height": 12}, "materials": {"m": {"type": "lambert"}},
                             "objects": [{"type": "sphere", "material": "m"}]}, spp=2)
    facetfit.write_image(str(tmp_path / "a.exr"), image)
    facetfit.write_image(str(tmp_path / "a.png"), image[..., :3])
    assert (tmp_path / "a.exr").stat().st_size > 0 and (tmp_path / "a.png").stat().st_size > 0
    with pytest.raises(ValueError, match=".exr or .png"):
        facetfit.write_image(str(tmp_path / "a.tif"), image)
    with pytest.raises(ValueError, match="NaN"):
        facetfit.write_image(str(tmp_path / "b.exr"), np.full((2, 2, 3), np.nan, np.float32))


def test_bad_inputs_raise_one_line(tmp_path):
    bad = tmp_path / "bad.binary"
    bad.write_bytes(b"\x01\x02")
    with pytest.raises(facetfit.Error) as e:
        facetfit.load(str(bad))
    assert "bad.binary" in str(e.value) and "\n" not in str(e.value)
    with pytest.raises(ValueError, match="refine"):
        facetfit.fit(GOLD, refine="some")
    with pytest.raises(facetfit.Error, match="type must be"):
        facetfit.material({"type": "phong"})
    # A path whose name is not UTF-8 (issue 47: "Unable to cast") is read as the bytes it is, and named in the error.
    odd = os.path.join(os.fsencode(str(tmp_path)), b"\xffodd.binary")
    with open(odd, "wb") as f:
        f.write(b"\x01\x02")
    for path in (odd, os.fsdecode(odd)):
        with pytest.raises(facetfit.Error) as e:
            facetfit.load(path)
        assert "odd.binary" in str(e.value) and "\udcff" in str(e.value)
    os.remove(odd)
    # Output names are file names (issue 47: "../x" and absolute names wrote outside out_dir, NUL lost the LUT).
    (tmp_path / "out").mkdir()
    for name, problem in [("../x", "holds a '/'"), (str(tmp_path / "abs"), "holds a '/'"), ("x\x00y", "control character")]:
        with pytest.raises(facetfit.Error, match=problem):
            facetfit.bake(GOLD, str(tmp_path / "out"), name=name, refine="none")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.binary", "out"] and not any((tmp_path / "out").iterdir())


def test_render_and_delta_e(gold_fit, tmp_path):
    lut = str(tmp_path / "gold.exr")
    gold_fit.write_lut(lut)
    scene = {
        "camera": {"position": [0, 0.6, 4], "look_at": [0, 0, 0], "fov": 30, "width": 48, "height": 48},
        "render": {"spp": 32},
        "environment": {"builtin": "sky"},
        "materials": {"m": {"type": "analytic", "file": GOLD}},
        "objects": [{"type": "sphere", "material": "m"}],
    }
    truth = facetfit.render(scene)
    assert truth.shape == (48, 48, 4) and truth.dtype == np.float32
    scene["materials"]["m"] = {"type": "lut", "file": lut}
    baked = facetfit.render(scene)
    mask = truth[..., 3] >= 1.0
    dmap, mean, worst = facetfit.delta_e(truth, baked, mask)
    assert dmap.shape == (48, 48) and mask.sum() > 500
    assert mean < 1.0 and worst >= mean
    assert facetfit.delta_e(truth, truth, mask)[1] == 0.0
    # Issue 47: NaN pixels gave 71.4 and five channels were taken; -1 samples per pixel was accepted.
    broken = truth.copy()
    broken[3, 5, 1] = np.nan
    with pytest.raises(ValueError, match=r"b\[3, 5\] is NaN or infinite"):
        facetfit.delta_e(truth, broken, mask)
    with pytest.raises(ValueError, match="3 or 4"):
        facetfit.delta_e(np.zeros((48, 48, 5), np.float32), truth)
    with pytest.raises(ValueError, match="spp"):
        facetfit.render(scene, spp=-1)
    # The memory budget is checked before allocating: one line, nothing rendered.
    big = dict(scene, camera=dict(scene["camera"], width=16384, height=16384))
    with pytest.raises(facetfit.Error, match="over the memory budget of 1.0 GiB"):
        facetfit.render(big, max_memory="1G")
    with pytest.raises(ValueError, match="max_memory"):
        facetfit.render(scene, max_memory="lots")
    # A scene file renders the same image as its dict.
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(scene))
    assert np.array_equal(facetfit.render(path), baked)


def test_the_package_ships_the_shaders_of_its_lut_format(tmp_path):
    # The shaders a farm compiles come with the module that bakes the LUTs they read.
    folder = facetfit.shader_dir()
    for name in ("facetfit_material.osl", "facetfit_preview.osl", "facetfit.h"):
        assert (folder / name).is_file(), name
    header = (folder / "facetfit.h").read_text()
    assert f"version >= 1 && version <= {facetfit.lut_format_version})" in header
    # A bake writes no newer format than the shaders read.
    f = facetfit.fit("builtin:gold-ggx-0.15")
    f.write_lut(tmp_path / "gold.exr")
    assert 1 <= facetfit.read_lut(tmp_path / "gold.exr").format_version <= facetfit.lut_format_version


def test_bad_angles_and_tolerances_raise_value_errors(tmp_path, gold_fit):
    # An angle outside the hemisphere or NaN, and a tolerance a LUT cannot store, are the caller's mistakes:
    # ValueError at once, never a value (D(nan) read as D(0)) or a LUT its reader refuses.
    for theta in (np.nan, -1.0, 2.0, [0.1, np.nan]):
        for curve in (gold_fit.D, gold_fit.slope_pdf):
            with pytest.raises(ValueError, match="theta"):
                curve(theta)
    assert np.isfinite(gold_fit.D([0.0, math.pi / 2])).all()
    for tolerance in (np.nan, -0.1, np.inf):
        with pytest.raises(ValueError, match="tolerance"):
            gold_fit.recommended(tolerance=tolerance)
        with pytest.raises(ValueError, match="tolerance"):
            gold_fit.write_lut(tmp_path / "g.exr", tolerance=tolerance)
        with pytest.raises(ValueError, match="tolerance"):
            facetfit.bake(GOLD, tmp_path / "out", tolerance=tolerance)
    assert not (tmp_path / "g.exr").exists()


def test_usd_is_what_export_writes(tmp_path):
    # Lut.usd is the command's NAME.usda; Lut.materialx its NAME.mtlx.
    facetfit.bake("builtin:red-plastic", str(tmp_path / "luts"), refine="none")
    lut_path = tmp_path / "luts" / "red-plastic.exr"
    lut = facetfit.read_lut(lut_path)
    command = os.path.join(os.path.dirname(sys.executable), "facetfit")
    subprocess.run([command, "export", "--usd", str(lut_path), "-o", str(tmp_path / "out")], check=True, capture_output=True)
    assert (tmp_path / "out" / "red_plastic.usda").read_text() == lut.usd("red-plastic")
    assert (tmp_path / "out" / "red_plastic.mtlx").read_text() == lut.materialx("red-plastic")
    assert "@./red_plastic.mtlx@</MaterialX/Materials/red_plastic>" in lut.usd("red-plastic")
