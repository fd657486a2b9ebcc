"""A fuzz harness over the public Python API (issue 47): hypothesis draws hostile values (NaN, infinities,
huge and denormal numbers, odd shapes and dtypes, random JSON, random bytes, random names) and every call
must return a defined result or raise one of the module's errors, never crash the interpreter, hang, or
write outside its folder. Derandomized, so that a run in `make test` is the same run each time."""
import math
import os

import numpy as np
import pytest

import facetfit

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402
from hypothesis.extra import numpy as hnp  # noqa: E402

GOLD = "builtin:gold-ggx-0.15"
FUZZ = settings(max_examples=150, deadline=None, derandomize=True, database=None,
                suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
EXPECTED = (facetfit.Error, ValueError, TypeError)

any_float = st.floats(allow_nan=True, allow_infinity=True) | st.sampled_from([1e300, -1e300, 5e-324, 1e-310, 0.0, -0.0])


def cast(a, dtype):
    with np.errstate(all="ignore"):
        return a.astype(dtype)


vectors = st.builds(cast, hnp.arrays(np.float64, st.tuples(st.integers(0, 4), st.sampled_from([2, 3, 3, 3, 4])), elements=any_float),
                    st.sampled_from([np.float64, np.float32, object]))
# Unit vectors in any direction, grazing ones included, so that the models' own code runs too.
units = hnp.arrays(np.float64, st.tuples(st.integers(1, 4), st.just(3)), elements=st.floats(-1, 1)).filter(
    lambda a: (np.linalg.norm(a, axis=1) > 1e-3).all()).map(lambda a: a / np.linalg.norm(a, axis=1, keepdims=True))
vectors = vectors | units

json_scalar = st.none() | st.booleans() | st.integers(-2**70, 2**70) | any_float | st.text(max_size=12)
json_value = st.recursive(json_scalar, lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=8), inner, max_size=4),
                          max_leaves=12)
material_keys = st.sampled_from(["type", "file", "alpha", "f0", "f82", "albedo", "stretch", "rotation", "tangent", "proposal",
                                 "slices", "anisotropic", "fresnel", "smith"])
material_types = st.sampled_from(["lambert", "ggx", "beckmann", "lut", "closures", "measured", "analytic", "lsq", "phong"])
materials = st.dictionaries(material_keys, json_value | material_types | st.just(GOLD), max_size=5)


@pytest.fixture(scope="module")
def models(tmp_path_factory):
    lut = str(tmp_path_factory.mktemp("fuzz") / "gold.exr")
    facetfit.fit(GOLD, refine="none").write_lut(lut)
    return [facetfit.material({"type": "ggx", "alpha": 0.2}), facetfit.read_lut(lut).model(), facetfit.load(GOLD),
            facetfit.material({"type": "measured", "file": GOLD, "proposal": lut}),
            facetfit.material({"type": "closures", "file": lut}),
            facetfit.material({"type": "lut", "file": lut, "stretch": [3, 0.5], "rotation": 30})]


def finite_or_nan(x):
    """Results are finite, or NaN where a measurement holds no value (Measurement.eval's convention)."""
    return not np.isinf(np.asarray(x, dtype=np.float64)).any()


@FUZZ
@given(o=vectors, i=vectors, which=st.integers(0, 5))
def test_models_take_any_array(models, o, i, which):
    model = models[which]
    try:
        f = model.eval(o, i)
    except EXPECTED:
        return
    assert finite_or_nan(f)
    if hasattr(model, "pdf"):
        assert np.isfinite(model.pdf(o, i)).all()
        s = model.sample(o, np.clip(np.nan_to_num(np.asarray(i, dtype=np.float64)), 0.0, 1.0))
        assert np.isfinite(s["pdf"]).all() and np.isfinite(s["weight"]).all()


@FUZZ
@given(description=materials)
def test_material_takes_any_dict(description):
    try:
        model = facetfit.material(description)
    except EXPECTED:
        return
    f = model.eval(np.array([0.0, 0.0, 1.0]), np.array([0.6, 0.0, 0.8]))
    assert np.isfinite(f).all()


@FUZZ
@given(scene=st.dictionaries(st.sampled_from(["camera", "render", "environment", "lights", "materials", "objects"]), json_value,
                             max_size=4))
def test_render_takes_any_scene(scene):
    scene.setdefault("materials", {"m": {"type": "lambert"}})
    scene.setdefault("objects", [{"type": "sphere", "material": "m"}])
    try:
        image = facetfit.render(scene, spp=1, max_memory="64M")
    except EXPECTED:
        return
    assert np.isfinite(image).all()


@FUZZ
@given(a=hnp.arrays(np.float32, st.tuples(st.integers(1, 4), st.integers(1, 4), st.integers(1, 5)), elements=any_float.map(
    lambda x: np.float32(x) if not math.isfinite(x) or abs(x) < 3e38 else np.float32(np.inf))), display=st.booleans())
def test_delta_e_takes_any_image(a, display):
    b = np.zeros_like(a)
    try:
        dmap, mean, worst = facetfit.delta_e(a, b, a_display_referred=display)
    except EXPECTED:
        return
    assert np.isfinite(dmap).all() and math.isfinite(mean) and math.isfinite(worst)


@FUZZ
@given(data=st.binary(max_size=4096), ext=st.sampled_from([".binary", ".bsdf", ".bin", ".exr"]))
def test_readers_take_any_bytes(tmp_path, data, ext):
    path = tmp_path / ("x" + ext)
    path.write_bytes(data)
    with pytest.raises(facetfit.Error):
        facetfit.read_lut(str(path)) if ext == ".exr" else facetfit.load(str(path))


@settings(FUZZ, max_examples=40)
@given(name=st.text(max_size=300))
def test_bake_names_stay_in_their_folder(tmp_path, name):
    out = tmp_path / "out"
    out.mkdir(exist_ok=True)
    try:
        facetfit.bake(GOLD, str(out), name=name, refine="none", sampling=False)
    except EXPECTED:
        pass
    assert sorted(os.listdir(tmp_path)) == ["out"]  # nothing beside the folder
    for entry in os.listdir(out):
        assert not os.path.isdir(out / entry) or entry == ".lock"
