"""The Python module against the command line that shares its Rust code
(issue 30): `bv eval`, `bv check --json`, `bv models --json`; sampling
against independent quadrature; bad input raising ValueError."""

import json
import math

import numpy as np
import pytest

import bv
from conftest import data

# The batch kernels' parity tolerance (crates/bv-core/tests/batch_parity.rs).
REL, ABS = 1e-4, 1e-6


def catalogue_ids():
    return [m["id"] for m in bv.models()]


def hemisphere(rng, n, min_cos=0.05, lower=False):
    """Unit directions with cos θ uniform in [min_cos, 1) (not grazing: the
    f32 rounding of a direction at the horizon is not what parity tests)."""
    z = rng.uniform(min_cos, 1.0, n)
    phi = rng.uniform(0, 2 * math.pi, n)
    s = np.sqrt(1 - z * z)
    d = np.stack([s * np.cos(phi), s * np.sin(phi), z], axis=1)
    if lower:
        d[:, 2] *= -1
    return d


def reads_a_file(mid):
    """Whether a catalogue model reads its data from a file (a `path`
    parameter: MERL, RGL), which its defaults cannot name."""
    decl = next(m for m in bv.models() if m["id"] == mid)
    return any(p["kind"] == "path" for p in decl["params"])


def buildable():
    """(id, Model) of every catalogue model with its defaults (the models
    that read a file are covered by test_file_models)."""
    out = []
    for mid in catalogue_ids():
        if reads_a_file(mid):
            continue
        out.append((mid, bv.Model(mid)))
    return out


def test_models_match_the_cli(bv_cli):
    p = bv_cli("models", "--json")
    assert p.returncode == 0, p.stderr
    assert bv.models() == json.loads(p.stdout)
    assert "cook-torrance" in catalogue_ids()


@pytest.mark.parametrize("precision", ["f64", "f32"])
def test_eval_equals_bv_eval_for_every_model(bv_eval, precision):
    rng = np.random.default_rng(30)
    for mid, m in buildable():
        n = 48
        wi = hemisphere(rng, n)
        wo = hemisphere(rng, n)
        if m.transmits:
            wo[n // 2 :] = hemisphere(rng, n - n // 2, lower=True)
        if precision == "f32":
            # The kernel sees f32 directions: the reference is f64 eval at
            # those same directions (as the parity test compares).
            wi = wi.astype(np.float32).astype(np.float64)
            wo = wo.astype(np.float32).astype(np.float64)
        got = m.eval(wi, wo, precision=precision)
        assert got.shape == (n, 3)
        assert got.dtype == (np.float64 if precision == "f64" else np.float32)
        params = m.params
        answers = bv_eval(
            [
                {"model": mid, "params": params, "wi": a.tolist(), "wo": b.tolist()}
                for a, b in zip(wi, wo)
            ]
        )
        assert len(answers) == n, (mid, answers[:3])
        want = np.array([a["f"] for a in answers])
        if precision == "f64":
            # Same f64 code; serde_json may read a direction one ulp off.
            np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-300, err_msg=mid)
        else:
            tol = np.maximum(REL * np.abs(want), ABS)
            bad = np.abs(got.astype(np.float64) - want) > tol
            assert not bad.any(), (mid, got[bad.any(axis=1)][:3], want[bad.any(axis=1)][:3])


def test_eval_broadcasts_one_direction():
    m = bv.Model("cook-torrance", alpha=0.3, fresnel="conductor", eta=[0.2, 0.92, 1.1])
    rng = np.random.default_rng(1)
    wo = hemisphere(rng, 100)
    wi = np.array([0.3, 0.0, math.sqrt(1 - 0.09)])
    a = m.eval(wi, wo, precision="f64")
    b = m.eval(np.tile(wi, (100, 1)), wo, precision="f64")
    np.testing.assert_array_equal(a, b)
    c = m.eval(wo, wi, precision="f64")
    assert c.shape == (100, 3)
    # Lambert is albedo/π exactly (closed form), in both precisions.
    lam = bv.Model("lambert", albedo=[0.2, 0.5, 0.8])
    want = np.array([0.2, 0.5, 0.8]) / math.pi
    np.testing.assert_allclose(lam.eval(wi, wo, "f64"), np.tile(want, (100, 1)), rtol=1e-15)
    np.testing.assert_allclose(lam.eval(wi, wo), np.tile(want, (100, 1)), rtol=1e-6)
    # An empty batch is an empty answer.
    assert lam.eval(np.zeros((0, 3)), np.zeros((0, 3))).shape == (0, 3)


@pytest.mark.parametrize(
    "mid,params",
    [
        ("lambert", {}),
        ("cook-torrance", {"alpha": 0.3}),
        ("ward", {"alpha_x": 0.2, "alpha_y": 0.1}),
        ("blinn-phong", {}),
        ("oren-nayar", {}),
        ("rough-dielectric", {}),
    ],
)
def test_sample_pdf_and_weight_are_consistent(mid, params):
    m = bv.Model(mid, **params)
    rng = np.random.default_rng(7)
    n = 20000
    wi = hemisphere(rng, 1, min_cos=0.3)[0]
    u = rng.uniform(0, 1, (n, 2))
    wo, weight, pdf = m.sample(wi, u)
    assert wo.shape == (n, 3) and weight.shape == (n, 3) and pdf.shape == (n,)
    ok = np.isfinite(wo).all(axis=1) & (pdf > 0)
    assert ok.mean() > 0.5, mid
    # pdf() agrees with the density sample() reported.
    np.testing.assert_allclose(m.pdf(wi, wo[ok]), pdf[ok], rtol=1e-9, err_msg=mid)
    # weight = f |cos θo| / pdf with f from the f64 reference.
    f = m.eval(wi, wo[ok], precision="f64")
    want = f * (np.abs(wo[ok, 2]) / pdf[ok])[:, None]
    np.testing.assert_allclose(weight[ok], want, rtol=1e-9, atol=1e-300, err_msg=mid)


@pytest.mark.parametrize(
    "mid,params", [("lambert", {}), ("cook-torrance", {"alpha": 0.3}), ("oren-nayar", {})]
)
def test_sampling_estimates_the_quadrature_albedo(mid, params):
    """The mean sample weight estimates ρhd; the reference is bv's
    deterministic quadrature (albedo()), a different estimator. Over several
    seeds the errors, in units of the sampling's own standard error, must
    look like draws of N(0, 1): none beyond 5, their RMS below 2."""
    m = bv.Model(mid, **params)
    theta = 40.0
    t = math.radians(theta)
    wi = np.array([math.sin(t), 0.0, math.cos(t)])
    ref, ref_err = m.albedo(theta)
    z = []
    for seed in range(8):
        u = np.random.default_rng(100 + seed).uniform(0, 1, (40000, 2))
        _, w, _ = m.sample(wi, u)
        mean = w.mean(axis=0)
        se = w.std(axis=0, ddof=1) / math.sqrt(len(w))
        for c in range(3):
            if se[c] > 0:
                z.append((mean[c] - ref[0, c]) / math.hypot(se[c], ref_err[0, c]))
            else:
                assert abs(mean[c] - ref[0, c]) < 1e-9
    z = np.array(z)
    assert np.all(np.abs(z) < 5), (mid, z)
    assert math.sqrt((z**2).mean()) < 2, (mid, z)


def test_albedo_of_lambert_is_its_albedo():
    m = bv.Model("lambert", albedo=[0.25, 0.5, 0.75])
    v, e = m.albedo([0, 30, 60, 89])
    assert v.shape == (4, 3) and e.shape == (4, 3)
    want = np.tile([0.25, 0.5, 0.75], (4, 1))
    assert np.all(np.abs(v - want) <= e + 1e-9)
    assert np.all(np.abs(v - want) < 1e-6)


def test_albedo_matches_bv_slice(bv_cli):
    m = bv.Model("ward", alpha_x=0.2)
    p = bv_cli("slice", "-m", "ward", "-p", "alpha_x=0.2", "--curve", "albedo", "--step", "20", "--json")
    assert p.returncode == 0, p.stderr
    s = json.loads(p.stdout)
    rows = np.array(s["rows"])
    v, e = m.albedo(rows[:, 0])
    np.testing.assert_allclose(v, rows[:, 1:4], rtol=1e-14)
    np.testing.assert_allclose(e.mean(axis=1), rows[:, 5], rtol=1e-12)


@pytest.mark.parametrize(
    "args,kwargs",
    [
        (["-m", "lambert", "-p", "albedo=0.8"], ("lambert", {"albedo": 0.8})),
        (["-m", "phong"], ("phong", {})),
        (["-m", "cook-torrance", "-p", "alpha=0.3"], ("cook-torrance", {"alpha": 0.3})),
        (["-m", data("retro.brdf")], (data("retro.brdf"), {})),
    ],
)
def test_check_equals_bv_check_json(bv_cli, args, kwargs):
    p = bv_cli("check", *args, "--json")
    assert p.returncode == 0, p.stderr
    want = json.loads(p.stdout)
    got = bv.Model(kwargs[0], **kwargs[1]).check()
    assert got == want


def test_file_models(bv_cli, tmp_path):
    retro = bv.Model(data("retro.brdf"))
    assert retro.check()["claims"] == {
        "reciprocal": None,
        "energy_conserving": None,
        "isotropic": None,
    }
    # A MERL table tabulated by the CLI, loaded by path.
    table = tmp_path / "lam.binary"
    p = bv_cli("tabulate", "-m", "lambert", "-p", "albedo=0.5", "--dims", "4,4,8", "--out", str(table))
    assert p.returncode == 0, p.stderr
    m = bv.Model(str(table))
    assert m.id == "merl"
    f = m.eval([0, 0, 1], [[0.6, 0, 0.8]], precision="f64")
    np.testing.assert_allclose(f, [[0.5 / math.pi] * 3], rtol=1e-6)
    # An RGL material written by the CLI, loaded by path: Lambert's value
    # within the round trip's tolerance away from the horizon.
    rgl = tmp_path / "lam.bsdf"
    p = bv_cli("tabulate", "-m", "lambert", "-p", "albedo=0.5", "--format", "rgl", "--out", str(rgl))
    assert p.returncode == 0, p.stderr
    m = bv.Model(str(rgl))
    assert m.id == "rgl"
    f = m.eval([0, 0, 1], [[0.6, 0, 0.8]], precision="f64")
    np.testing.assert_allclose(f, [[0.5 / math.pi] * 3], rtol=0.1)
    assert m.check()["claims"]["energy_conserving"] is None


@pytest.mark.parametrize(
    "query",
    [
        {"model": "nope"},
        {"model": "lambert", "params": {"albedo": 2}},
        {"model": "lambert", "params": {"rho": 0.3}},
        {"model": "cook-torrance", "params": {"fresnel": "copper"}},
        {"model": "lambert", "params": {"albedo": [0.1, 0.2]}},
    ],
)
def test_bad_models_raise_bvs_message(bv_eval, query):
    ans = bv_eval([{**query, "wi": [0, 0, 1], "wo": [0, 0, 1]}])[0]
    assert "error" in ans
    with pytest.raises(ValueError) as e:
        bv.Model(query["model"], **query.get("params", {}))
    # The same message; the list of known models may hold the user files
    # this process has loaded besides the catalogue.
    if "known models" in ans["error"]:
        assert str(e.value).startswith(ans["error"].rstrip(")")), (str(e.value), ans)
    else:
        assert str(e.value) == ans["error"]


def test_missing_files_raise(tmp_path):
    for path in [tmp_path / "none.brdf", tmp_path / "none.binary"]:
        with pytest.raises(ValueError) as e:
            bv.Model(str(path))
        assert "none." in str(e.value)
    with pytest.raises(ValueError):
        bv.Model(data("broken_syntax.brdf"))
    with pytest.raises(ValueError):
        bv.Model("merl")  # no file given
    with pytest.raises(ValueError):
        bv.Model(3)


def test_bad_arrays_raise_value_error():
    m = bv.Model("lambert")
    up = np.array([[0.0, 0.0, 1.0]] * 4)
    bad = [
        (np.zeros((4, 2)), up),  # not 3 columns
        (np.zeros((4, 3, 1)), up),  # 3-D
        (up, np.array([[0.0, 0.0, 1.0]] * 3)),  # 4 against 3 rows
        (np.array([[np.nan, 0.0, 1.0]]), up),  # NaN
        (np.array([[0.0, 0.0, np.inf]]), up),  # infinite
        (np.array([[0.0, 0.0, 2.0]]), up),  # not unit length
        (np.array([[0.0, 0.0, 0.0]]), up),  # zero
        ("up", up),  # not numbers
    ]
    for wi, wo in bad:
        for precision in ("f32", "f64"):
            with pytest.raises(ValueError):
                m.eval(wi, wo, precision=precision)
        with pytest.raises(ValueError):
            m.pdf(wi, wo)
    # The message names the row, as bv eval names the direction.
    wi = up.copy()
    wi[2] = [np.nan, 0, 1]
    with pytest.raises(ValueError, match=r"wi\[2\].*not finite"):
        m.eval(wi, up)
    with pytest.raises(ValueError, match="precision"):
        m.eval(up, up, precision="f16")
    for u in [np.full((4, 2), 1.0), np.full((4, 2), np.nan), np.zeros((4, 3)), np.zeros((3, 2))]:
        with pytest.raises(ValueError):
            m.sample(up, u)
    for t in [-1, 91, np.nan, [[1, 2]]]:
        with pytest.raises(ValueError):
            m.albedo(t)
    with pytest.raises(ValueError):
        m.check(albedo="guess")
    with pytest.raises(ValueError):
        bv.Model("lambert", albedo=float("nan"))


def test_help_is_useful():
    assert "cook-torrance" in bv.__doc__
    for f in [bv.Model, bv.Model.eval, bv.Model.sample, bv.Model.pdf, bv.Model.albedo, bv.Model.check, bv.models]:
        assert f.__doc__ and len(f.__doc__) > 60, f


def test_render_returns_the_size_asked_and_not_blank(tmp_path):
    m = bv.Model("cook-torrance", alpha=0.3)
    for view in ["lobe3d", "polar"]:
        fig = bv.render(m, view=view, width=320, height=240, theta_i=30, theme="light")
        assert isinstance(fig, bv.Figure) and isinstance(fig, np.ndarray)
        assert fig.shape == (240, 320, 4) and fig.dtype == np.uint8
        # Not blank: many distinct colours, not one background.
        colours = np.unique(fig.reshape(-1, 4), axis=0)
        assert len(colours) > 20, (view, len(colours))
        png = fig._repr_png_()
        assert png.startswith(b"\x89PNG\r\n\x1a\n")
        # The PNG decodes back to the same pixels (zlib + the scanline filter byte).
        import struct
        import zlib

        idat = b""
        pos = 8
        while pos < len(png):
            (n,) = struct.unpack(">I", png[pos : pos + 4])
            tag = png[pos + 4 : pos + 8]
            if tag == b"IDAT":
                idat += png[pos + 8 : pos + 8 + n]
            pos += 12 + n
        raw = np.frombuffer(zlib.decompress(idat), dtype=np.uint8).reshape(240, 1 + 320 * 4)
        np.testing.assert_array_equal(raw[:, 1:].reshape(240, 320, 4), np.asarray(fig))
    fig.save(tmp_path / "f.png")
    assert (tmp_path / "f.png").read_bytes() == png
    with pytest.raises(ValueError, match="view"):
        bv.render(m, view="nope")
    with pytest.raises(ValueError):
        bv.render(m, width=0)
    with pytest.raises(ValueError):
        bv.render(m, theta_i=float("nan"))
    with pytest.raises(ValueError):
        bv.render("lambert")
