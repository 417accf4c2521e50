#!/usr/bin/env python3
"""A batch study on Dask: every BRDF file of a folder × several analytic
models, one task per (file, model) pair and one per file, each calling the
`bv` module; the results gathered into one table (CSV on stdout or --out).

    python dask_study.py FOLDER                          # a LocalCluster on this machine
    python dask_study.py FOLDER --scheduler tcp://scheduler:8786 --out study.csv
    python dask_study.py FOLDER -m lambert -m "cook-torrance alpha=0.3 fresnel=conductor eta=0.2,0.92,1.1"

The files are user `.brdf` files, MERL `.binary` tables and RGL `.bsdf`
materials (anything `bv.Model(path)` opens); other files are listed as
skipped. For each file, one task computes its directional albedo ρhd at the
--theta angles (with bv's error estimate) and the verdicts of `bv check`
(energy, reciprocity). For each (file, model) pair, one task computes the
model's albedo at the same angles and how far the model is from the file:
the RMS difference of log(1 + f·cos θo) over a fixed set of direction
pairs. With --fit, each pair task first fits the model's parameters to the
file (`bv.fit`, Löw et al. 2012's E2 metric, the parameters given here as
the start) and reports the fitted parameters, the fit's error and the
fitted model's albedo and distance; without it the models keep the
parameters given here, and the distance ranks them at those.

On a real cluster every worker needs the `bv` module (`pip install
./python` from bv's repository) and must see the folder at the same path (a
shared file system); the tasks' code travels with them (run as a script,
the functions are pickled by value; imported as a module, `run_study`
uploads this file to the workers), so the workers need only `bv`.
"""

from __future__ import annotations

import argparse
import csv
import io
import math
import os
import sys
from typing import Any, Dict, List, Sequence, Tuple

import numpy as np

import bv

# What bv.Model(path) opens: user files, MERL tables, RGL materials.
EXTENSIONS = (".brdf", ".binary", ".bsdf")

DEFAULT_MODELS = [
    "lambert",
    "oren-nayar",
    "cook-torrance alpha=0.3",
    "ward alpha_x=0.2 alpha_y=0.2",
]

DEFAULT_THETAS = (0.0, 30.0, 60.0)

COLUMNS = [
    "file",
    "model",
    "params",
    "fit_error",
    "theta_i",
    "rho_file",
    "rho_file_err",
    "rho_model",
    "rho_model_err",
    "rms_log_diff",
    "file_conserves_energy",
    "file_reciprocal",
]


def parse_model(text: str) -> Tuple[str, Dict[str, Any]]:
    """``"cook-torrance alpha=0.3 eta=0.2,0.92,1.1"`` → (id, params):
    numbers become floats, comma lists lists of floats, the rest strings."""
    words = text.split()
    if not words:
        raise ValueError("an empty model")
    params: Dict[str, Any] = {}
    for w in words[1:]:
        if "=" not in w:
            raise ValueError(f"{text!r}: expected NAME=VALUE after the model id, found {w!r}")
        k, v = w.split("=", 1)
        try:
            params[k] = [float(x) for x in v.split(",")] if "," in v else float(v)
        except ValueError:
            params[k] = v
    return words[0], params


def directions(n: int = 256, min_cos: float = 0.05) -> np.ndarray:
    """A fixed Fibonacci set of ``n`` upper-hemisphere directions with
    cos θ in [min_cos, 1) (the same on every worker)."""
    k = np.arange(n) + 0.5
    z = 1.0 - (1.0 - min_cos) * k / n
    phi = k * math.pi * (3.0 - math.sqrt(5.0))
    s = np.sqrt(1.0 - z * z)
    return np.stack([s * np.cos(phi), s * np.sin(phi), z], axis=1)


def incident(theta_deg: float) -> np.ndarray:
    t = math.radians(theta_deg)
    return np.array([math.sin(t), 0.0, math.cos(t)])


def log_cos_weighted(m: "bv.Model", theta_deg: float, wo: np.ndarray) -> np.ndarray:
    """log(1 + f·cos θo) at light ``theta_deg`` over ``wo``, f64 path."""
    f = m.eval(incident(theta_deg), wo, precision="f64")
    return np.log1p(f * wo[:, 2:3])


def file_task(path: str, thetas: Sequence[float]) -> Dict[str, Any]:
    """Per file: ρhd (mean of RGB) and its error at each θi, and `bv
    check`'s energy and reciprocity verdicts."""
    m = bv.Model(path)
    rho, err = m.albedo(list(thetas))
    report = m.check()
    return {
        "file": path,
        "rho": rho.mean(axis=1).tolist(),
        "err": err.mean(axis=1).tolist(),
        "conserves": bool(report["energy"]["conserves"]),
        "reciprocal": bool(report["reciprocity"]["reciprocal"]),
    }


def pair_task(
    path: str, model: str, thetas: Sequence[float], fit: bool = False
) -> Dict[str, Any]:
    """Per (file, model): with ``fit``, the model fitted to the file first
    (``bv.fit``, metric E2, one start at the given parameters); then the
    model's ρhd and error at each θi, and the RMS difference of
    log(1 + f·cos θo) between model and file over every θi and the fixed
    direction set."""
    mid, params = parse_model(model)
    m = bv.Model(mid, **params)
    f = bv.Model(path)
    fit_error = None
    if fit:
        r = bv.fit(m, to=f, metric="e2", starts=1)
        m, fit_error = r.model, r.error
    rho, err = m.albedo(list(thetas))
    wo = directions()
    sq = [
        (log_cos_weighted(m, t, wo) - log_cos_weighted(f, t, wo)) ** 2 for t in thetas
    ]
    return {
        "file": path,
        "model": mid,
        "params": m.params,
        "fit_error": fit_error,
        "rho": rho.mean(axis=1).tolist(),
        "err": err.mean(axis=1).tolist(),
        "rms_log_diff": float(math.sqrt(np.mean(sq))),
    }


def study_files(folder: str) -> Tuple[List[str], List[str]]:
    """(files bv opens, other files skipped), sorted."""
    names = sorted(os.listdir(folder))
    paths = [os.path.join(folder, n) for n in names if os.path.isfile(os.path.join(folder, n))]
    keep = [p for p in paths if p.lower().endswith(EXTENSIONS)]
    return keep, [p for p in paths if p not in keep]


def run_study(
    client: Any,
    folder: str,
    models: Sequence[str] = DEFAULT_MODELS,
    thetas: Sequence[float] = DEFAULT_THETAS,
    fit: bool = False,
) -> List[Dict[str, Any]]:
    """Submits one task per file and one per (file, model) pair to the
    Dask ``client`` (``fit``: each pair's model fitted to its file first),
    gathers them, and returns the table's rows (one per pair and θi, in
    file, model, θi order)."""
    if __name__ != "__main__":
        # Imported as a module (a test, a notebook): the tasks name its
        # functions by module, so the workers get this file (run as a
        # script, the functions travel by value with the tasks).
        client.upload_file(__file__)
    files, _ = study_files(folder)
    for text in models:
        parse_model(text)  # bad model text fails here, not on a worker
    thetas = [float(t) for t in thetas]
    per_file = client.map(file_task, files, thetas=thetas, pure=False)
    pairs = [(f, m) for f in files for m in models]
    per_pair = client.map(
        pair_task, [f for f, _ in pairs], [m for _, m in pairs], thetas=thetas, fit=fit,
        pure=False,
    )
    file_rows = {r["file"]: r for r in client.gather(per_file)}
    rows = []
    for r in client.gather(per_pair):
        fr = file_rows[r["file"]]
        for k, t in enumerate(thetas):
            rows.append(
                {
                    "file": os.path.basename(r["file"]),
                    "model": r["model"],
                    "params": " ".join(f"{k2}={v}" for k2, v in sorted(r["params"].items())),
                    "fit_error": "" if r["fit_error"] is None else r["fit_error"],
                    "theta_i": t,
                    "rho_file": fr["rho"][k],
                    "rho_file_err": fr["err"][k],
                    "rho_model": r["rho"][k],
                    "rho_model_err": r["err"][k],
                    "rms_log_diff": r["rms_log_diff"],
                    "file_conserves_energy": fr["conserves"],
                    "file_reciprocal": fr["reciprocal"],
                }
            )
    return rows


def to_csv(rows: List[Dict[str, Any]]) -> str:
    out = io.StringIO()
    w = csv.DictWriter(out, fieldnames=COLUMNS, lineterminator="\n")
    w.writeheader()
    for r in rows:
        w.writerow({k: (repr(v) if isinstance(v, float) else v) for k, v in r.items()})
    return out.getvalue()


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("folder", help="a folder of .brdf / .binary / .bsdf files")
    ap.add_argument("--scheduler", help="a Dask scheduler's address (tcp://host:8786); "
                    "default: a LocalCluster of worker processes on this machine")
    ap.add_argument("--workers", type=int, default=2, help="LocalCluster workers (default 2)")
    ap.add_argument("-m", "--model", action="append", dest="models",
                    help='a model with parameters, "ID NAME=VALUE …" (repeatable; '
                    f"default: {', '.join(DEFAULT_MODELS)})")
    ap.add_argument("--theta", type=float, action="append", dest="thetas",
                    help="light polar angle in degrees (repeatable; default 0, 30, 60)")
    ap.add_argument("--fit", action="store_true",
                    help="fit each model to each file first (bv.fit, metric E2)")
    ap.add_argument("--out", help="write the CSV table here (default: stdout)")
    a = ap.parse_args(argv)

    models = a.models or DEFAULT_MODELS
    for text in models:
        try:
            mid, params = parse_model(text)
            bv.Model(mid, **params)
        except ValueError as e:
            print(f"dask_study: --model {text!r}: {e}", file=sys.stderr)
            return 2

    from dask.distributed import Client, LocalCluster

    files, skipped = study_files(a.folder)
    for s in skipped:
        print(f"dask_study: skipped {s} (not a .brdf, .binary or .bsdf file)", file=sys.stderr)
    if not files:
        print(f"dask_study: no BRDF files in {a.folder}", file=sys.stderr)
        return 1
    if a.scheduler:
        client = Client(a.scheduler)
        cluster = None
    else:
        cluster = LocalCluster(n_workers=a.workers, threads_per_worker=1, processes=True)
        client = Client(cluster)
    try:
        rows = run_study(client, a.folder, models, a.thetas or DEFAULT_THETAS, fit=a.fit)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    text = to_csv(rows)
    if a.out:
        with open(a.out, "w") as f:
            f.write(text)
        print(f"dask_study: wrote {a.out} ({len(rows)} rows)", file=sys.stderr)
    else:
        sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
