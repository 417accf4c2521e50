"""python/examples/dask_study.py on a 2-worker LocalCluster (worker
processes) over a folder the test makes, its table checked against direct
calls of the module in this process; and the script run as a command."""

import csv
import importlib.util
import io
import math
import shutil
import subprocess
import sys

import numpy as np
import pytest

import bv
from conftest import ROOT, data, need

SCRIPT = ROOT / "python" / "examples" / "dask_study.py"
MODELS = ["lambert albedo=0.5", "cook-torrance alpha=0.3 fresnel=conductor eta=0.2,0.92,1.1"]
THETAS = [0.0, 45.0]


def load_study():
    spec = importlib.util.spec_from_file_location("dask_study", SCRIPT)
    mod = importlib.util.module_from_spec(spec)
    sys.modules["dask_study"] = mod
    spec.loader.exec_module(mod)
    return mod


@pytest.fixture(scope="module")
def folder(tmp_path_factory, bv_cli):
    d = tmp_path_factory.mktemp("study")
    for name in ["lambert.brdf", "ward.brdf", "retro.brdf"]:
        shutil.copy(data(name), d / name)
    p = bv_cli("tabulate", "-m", "phong", "--dims", "8,8,16", "--out", str(d / "phong.binary"))
    assert p.returncode == 0, p.stderr
    (d / "notes.txt").write_text("not a BRDF\n")
    return d


def fibonacci(n=256, min_cos=0.05):
    """The study's fixed direction set, written out again here."""
    out = []
    for i in range(n):
        k = i + 0.5
        z = 1 - (1 - min_cos) * k / n
        phi = k * math.pi * (3 - math.sqrt(5))
        s = math.sqrt(1 - z * z)
        out.append([s * math.cos(phi), s * math.sin(phi), z])
    return np.array(out)


def rms_log_diff(model, file, thetas):
    wo = fibonacci()
    total, count = 0.0, 0
    for t in thetas:
        wi = [math.sin(math.radians(t)), 0.0, math.cos(math.radians(t))]
        a = np.log1p(model.eval(wi, wo, precision="f64") * wo[:, 2:3])
        b = np.log1p(file.eval(wi, wo, precision="f64") * wo[:, 2:3])
        total += float(((a - b) ** 2).sum())
        count += a.size
    return math.sqrt(total / count)


def test_study_on_a_local_cluster_matches_direct_calls(folder):
    distributed = need("dask.distributed")
    study = load_study()
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        assert len(client.scheduler_info()["workers"]) == 2
        rows = study.run_study(client, str(folder), MODELS, THETAS)
        # The tasks ran in the workers' processes, not here.
        ran = client.run(lambda: "bv" in sys.modules)
        assert len(ran) == 2
    files = ["lambert.brdf", "phong.binary", "retro.brdf", "ward.brdf"]
    assert len(rows) == len(files) * len(MODELS) * len(THETAS)
    assert [r["file"] for r in rows[:: len(MODELS) * len(THETAS)]] == files
    for name in files:
        f = bv.Model(str(folder / name))
        rho_f, err_f = f.albedo(THETAS)
        report = f.check()
        for text in MODELS:
            mid, _, rest = text.partition(" ")
            params = {}
            for w in rest.split():
                k, v = w.split("=")
                params[k] = [float(x) for x in v.split(",")] if "," in v else (
                    float(v) if v[0].isdigit() else v)
            m = bv.Model(mid, **params)
            rho_m, err_m = m.albedo(THETAS)
            mine = [r for r in rows if r["file"] == name and r["model"] == mid]
            assert [r["theta_i"] for r in mine] == THETAS
            want = rms_log_diff(m, f, THETAS)
            for k, r in enumerate(mine):
                # The same deterministic estimators (quadrature, or Monte
                # Carlo seeded by the angle's index), called directly.
                assert r["rho_file"] == pytest.approx(rho_f[k].mean(), rel=1e-12)
                assert r["rho_file_err"] == pytest.approx(err_f[k].mean(), rel=1e-12)
                assert r["rho_model"] == pytest.approx(rho_m[k].mean(), rel=1e-12)
                assert r["rho_model_err"] == pytest.approx(err_m[k].mean(), rel=1e-12)
                assert r["rms_log_diff"] == pytest.approx(want, rel=1e-9, abs=1e-15)
                assert r["file_conserves_energy"] == report["energy"]["conserves"]
                assert r["file_reciprocal"] == report["reciprocity"]["reciprocal"]
    # Closed forms: the Lambert file and the Lambert model of the same
    # albedo are the same function, 0.5/π (distance 0 up to the f32
    # arithmetic of the user-file interpreter, ~1e-8), of albedo 0.5 at
    # every θi.
    same = [r for r in rows if r["file"] == "lambert.brdf" and r["model"] == "lambert"]
    for r in same:
        assert r["rms_log_diff"] < 1e-7
        assert abs(r["rho_file"] - 0.5) <= max(3 * r["rho_file_err"], 1e-7)
        assert abs(r["rho_model"] - 0.5) < 1e-9
    # A different model is at a clearly nonzero distance.
    other = [r for r in rows if r["file"] == "lambert.brdf" and r["model"] == "cook-torrance"]
    assert all(r["rms_log_diff"] > 1e-3 for r in other)


def test_study_as_a_command(folder, tmp_path):
    need("dask.distributed")
    out = tmp_path / "study.csv"
    args = [sys.executable, str(SCRIPT), str(folder), "--workers", "2", "--out", str(out)]
    for m in MODELS:
        args += ["-m", m]
    for t in THETAS:
        args += ["--theta", str(t)]
    p = subprocess.run(args, capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr
    assert "skipped" in p.stderr and "notes.txt" in p.stderr
    rows = list(csv.DictReader(io.StringIO(out.read_text())))
    assert len(rows) == 4 * len(MODELS) * len(THETAS)
    # The same numbers as the module's own calls.
    ward = bv.Model(str(folder / "ward.brdf"))
    rho, _ = ward.albedo(THETAS)
    got = [float(r["rho_file"]) for r in rows if r["file"] == "ward.brdf" and r["model"] == "lambert"]
    np.testing.assert_allclose(got, rho.mean(axis=1), rtol=1e-12)
    # A bad model is refused before anything is submitted.
    p = subprocess.run(
        [sys.executable, str(SCRIPT), str(folder), "-m", "lambert albedo"],
        capture_output=True, text=True, timeout=600,
    )
    assert p.returncode != 0 and "NAME=VALUE" in p.stderr


def test_study_fits_each_model_to_each_file(tmp_path):
    """With fit=True each pair's model is fitted to its file on a worker:
    Lambert fitted to the Lambert file lands on the file's own albedo (the
    fit error and the distance drop to ~0), as a direct bv.fit does."""
    distributed = need("dask.distributed")
    study = load_study()
    shutil.copy(data("lambert.brdf"), tmp_path / "lambert.brdf")
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        plain = study.run_study(client, str(tmp_path), ["lambert albedo=0.9"], [30.0])
        fitted = study.run_study(client, str(tmp_path), ["lambert albedo=0.9"], [30.0], fit=True)
    assert plain[0]["fit_error"] == "" and fitted[0]["fit_error"] != ""
    direct = bv.fit(
        bv.Model("lambert", albedo=0.9), to=bv.Model(str(data("lambert.brdf"))),
        metric="e2", starts=1,
    )
    assert fitted[0]["fit_error"] == pytest.approx(direct.error, rel=1e-9)
    assert fitted[0]["rms_log_diff"] < 1e-4 < plain[0]["rms_log_diff"]
    assert fitted[0]["rho_model"] == pytest.approx(fitted[0]["rho_file"], abs=2e-3)
