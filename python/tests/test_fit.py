"""bv.fit against `bv fit --json` and against known parameters."""

import json

import pytest

import bv


def test_fit_recovers_known_parameters():
    # A Ward target with known values; the fit starts from the defaults.
    target = bv.Model("ward", kd=0.2, ks=0.3, alpha=0.15)
    r = bv.fit(bv.Model("ward"), to=target, free="kd,ks,alpha")
    p = r.model.params

    def rgb(v):
        return v if isinstance(v, list) else [v] * 3

    assert p["alpha_x"] == pytest.approx(0.15, rel=0.01)
    assert p["alpha_y"] == pytest.approx(0.15, rel=0.01)
    assert rgb(p["ks"]) == pytest.approx([0.3] * 3, rel=0.01)
    assert rgb(p["kd"]) == pytest.approx([0.2] * 3, rel=0.01)
    assert r.error < 1e-4 < r.initial_error
    assert isinstance(r.model, bv.Model) and r.model.id == "ward"
    assert r.metric == "ngan" and r.pairs > 1000 and r.iterations >= 1
    assert {"theta_i_min", "theta_i_max", "error", "samples"} <= set(r.residuals[0])


def test_fit_is_what_the_command_line_finds(bv_cli):
    target = bv.Model("cook-torrance", distribution="ggx", alpha=0.2, kd=0.0)
    r = bv.fit(bv.Model("blinn-phong"), to=target, metric="e2", starts=2)
    out = bv_cli(
        "fit", "-m", "blinn-phong", "--to", "cook-torrance",
        "--to-param", "distribution=ggx", "--to-param", "alpha=0.2", "--to-param", "kd=0",
        "--metric", "e2", "--starts", "2", "--json",
    )
    assert out.returncode == 0, out.stderr
    cli = json.loads(out.stdout)
    assert cli["metric"] == r.metric == "e2"
    assert r.error == pytest.approx(cli["error"], rel=1e-9)
    assert r.free == cli["free"]
    for k, v in cli["params"].items():
        assert r.model.params[k] == pytest.approx(v, rel=1e-9), k


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"metric": "l2"}, "metric"),
        ({"starts": 0}, "starts"),
        ({"free": "no_such"}, "no_such"),
    ],
)
def test_fit_refuses_bad_input(kwargs, message):
    with pytest.raises(ValueError, match=message):
        bv.fit(bv.Model("ward"), to=bv.Model("lambert"), **kwargs)


def test_fit_needs_models():
    with pytest.raises(ValueError, match="bv.Model"):
        bv.fit("ward", to=bv.Model("lambert"))
