"""Shared helpers: the `bv` binary the module is compared with."""

import json
import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


def bv_binary() -> str:
    """The command-line `bv` built from the same tree: $BV_BIN, else
    $CARGO_TARGET_DIR/debug/bv, else target/debug/bv. Missing is a failure,
    not a skip: the comparisons are the point of these tests."""
    if os.environ.get("BV_BIN"):
        return os.environ["BV_BIN"]
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    path = target / "debug" / "bv"
    if not path.exists():
        raise RuntimeError(f"no bv binary at {path}: build it (cargo build) or set BV_BIN")
    return str(path)


@pytest.fixture(scope="session")
def bv_cli():
    """Runs `bv ARGS…` and returns the completed process (text mode)."""
    exe = bv_binary()

    def run(*args, stdin=""):
        return subprocess.run(
            [exe, *args], input=stdin, capture_output=True, text=True, timeout=600
        )

    return run


@pytest.fixture(scope="session")
def bv_eval(bv_cli):
    """Answers of `bv eval` for a list of queries (dicts): a list of the
    JSON answers, in order."""

    def run(queries):
        text = "".join(json.dumps(q) + "\n" for q in queries)
        p = bv_cli("eval", stdin=text)
        return [json.loads(line) for line in p.stdout.splitlines()]

    return run


def data(name: str) -> str:
    """A user `.brdf` file of the Rust tests."""
    return str(ROOT / "tests" / "data" / "brdf" / name)


def need(module: str):
    """Imports an optional test dependency (nbclient, dask.distributed).
    Missing is a failure under CI (BV_CI=1, set by .ci/python.sh, which
    installs them), a skip elsewhere."""
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError as e:
        if os.environ.get("BV_CI") == "1":
            raise RuntimeError(
                f"{module} is not installed in the CI virtual environment: {e}"
            ) from e
        pytest.skip(f"{module} is not installed ({e}); .ci/python.sh installs it")
