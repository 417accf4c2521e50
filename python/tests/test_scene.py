"""bv.Scene (scene files read and written by the app's own code) and
bv.render of a whole scene, against `bv scene new` / `bv scene check`."""

import numpy as np
import pytest

import bv


def new_scene(bv_cli, path, *args):
    """A scene file written by `bv scene new ARGS… --out PATH`."""
    p = bv_cli("scene", "new", *args, "--out", str(path))
    assert p.returncode == 0, p.stderr
    return path


TWO = ["-m", "lambert", "-p", "albedo=0.3", "-m", "cook-torrance", "-p", "alpha=0.2",
       "--theta-i", "40", "--phi-i", "20", "--log"]


def test_load_save_load_round_trip(bv_cli, tmp_path):
    f = new_scene(bv_cli, tmp_path / "two.toml", *TWO)
    s = bv.Scene.load(f)
    assert [b["id"] for b in s.brdfs] == ["lambert", "cook-torrance"]
    assert s.brdfs[0]["params"]["albedo"] == [0.3, 0.3, 0.3]
    assert s.brdfs[1]["params"]["alpha_x"] == 0.2
    assert (s.theta_i, s.phi_i, s.log, s.cosine, s.theme) == (40.0, 20.0, True, False, "dark")
    assert s.warnings == []
    out = tmp_path / "sub" / "again.toml"
    out.parent.mkdir()
    s.save(out)
    t = bv.Scene.load(out)
    assert t == s
    assert t.to_toml() == s.to_toml()
    # What bv writes is what `bv scene print` prints for it.
    p = bv_cli("scene", "print", str(out))
    assert p.returncode == 0, p.stderr
    assert out.read_text() == p.stdout
    # And the CLI reads the file Python wrote.
    p = bv_cli("scene", "check", str(out))
    assert p.returncode == 0, p.stderr
    assert "2 BRDFs: lambert, cook-torrance" in p.stdout
    # Something different is not equal.
    other = bv.Scene.load(new_scene(bv_cli, tmp_path / "one.toml", "-m", "lambert"))
    assert other != s


def test_scene_from_models_is_what_bv_scene_new_writes(bv_cli, tmp_path):
    s = bv.Scene(
        [bv.Model("lambert", albedo=0.3), bv.Model("cook-torrance", alpha=0.2)],
        theta_i=40, phi_i=20, log=True,
    )
    assert s == bv.Scene.load(new_scene(bv_cli, tmp_path / "two.toml", *TWO))
    assert [m.id for m in s.models] == ["lambert", "cook-torrance"]
    np.testing.assert_array_equal(
        s.models[1].eval([0, 0, 1], [[0.6, 0, 0.8]], precision="f64"),
        bv.Model("cook-torrance", alpha=0.2).eval([0, 0, 1], [[0.6, 0, 0.8]], precision="f64"),
    )
    light = bv.Scene([bv.Model("ward")], theme="light", cosine=True)
    assert light.theme == "light" and light.cosine
    # The light out of range is refused as `bv scene new` refuses it.
    with pytest.raises(ValueError):
        bv.Scene([bv.Model("lambert")], theta_i=200)
    with pytest.raises(ValueError):
        bv.Scene(["lambert"])
    with pytest.raises(ValueError):
        bv.Scene([bv.Model("lambert")], theme="sepia")


@pytest.mark.parametrize(
    "name,text",
    [
        ("missing.toml", None),
        ("not-toml.toml", "this is = = not toml\n"),
        ("no-version.toml", 'format = "bv-scene"\n'),
        ("wrong-format.toml", 'format = "mitsuba"\nversion = 1\n'),
        (
            "bad-model.toml",
            'format = "bv-scene"\nversion = 1\n[[brdfs]]\nid = 1\ncolor = [1, 2, 3]\n'
            'visible = true\n[brdfs.spec]\nmodel = "nope"\n',
        ),
        (
            "bad-param.toml",
            'format = "bv-scene"\nversion = 1\n[[brdfs]]\nid = 1\ncolor = [1, 2, 3]\n'
            'visible = true\n[brdfs.spec]\nmodel = "lambert"\n[brdfs.spec.params]\nalbedo = 7\n',
        ),
        ("missing-table.toml", 'format = "bv-scene"\nversion = 1\n[[brdfs]]\nid = 1\n'
         'color = [1, 2, 3]\nvisible = true\n[brdfs.spec]\nmodel = "merl"\n'
         '[brdfs.spec.params]\npath = "none.binary"\n'),
    ],
)
def test_bad_scene_files_raise_bv_scene_checks_message(bv_cli, tmp_path, name, text):
    path = tmp_path / name
    if text is not None:
        path.write_text(text)
    p = bv_cli("scene", "check", str(path))
    assert p.returncode == 1, (p.stdout, p.stderr)
    want = p.stderr.strip()
    assert want.startswith("bv: ")
    with pytest.raises(ValueError) as e:
        bv.Scene.load(path)
    # The list of known models may hold user files this process loaded.
    if "known models" in want:
        assert str(e.value).startswith(want[4:].split("(known models")[0]), (str(e.value), want)
    else:
        assert str(e.value) == want[4:]


def test_unknown_keys_warn(bv_cli, tmp_path):
    f = new_scene(bv_cli, tmp_path / "s.toml", "-m", "lambert")
    text = f.read_text().replace('format = "bv-scene"', 'format = "bv-scene"\nflavour = "mint"')
    f.write_text(text)
    with pytest.warns(UserWarning, match="flavour"):
        s = bv.Scene.load(f)
    assert any("flavour" in w for w in s.warnings)


def test_save_errors_raise(tmp_path):
    s = bv.Scene([bv.Model("lambert")])
    with pytest.raises(ValueError, match="no-such-folder"):
        s.save(tmp_path / "no-such-folder" / "s.toml")
    # The folder itself is not a file to write.
    with pytest.raises(ValueError):
        s.save(tmp_path)


def colours(img):
    return len(np.unique(np.asarray(img).reshape(-1, 4), axis=0))


def test_render_scene(bv_cli, tmp_path):
    s = bv.Scene.load(new_scene(bv_cli, tmp_path / "two.toml", *TWO))
    for view in ["polar", "lobe3d"]:
        fig = bv.render(s, view=view, width=320, height=240)
        assert isinstance(fig, bv.Figure)
        assert fig.shape == (240, 320, 4) and fig.dtype == np.uint8
        assert colours(fig) > 20, view
        # The first model alone, with the same light and theme, draws
        # something else: the scene's second BRDF is in the figure.
        first = bv.render(s.models[0], view=view, width=320, height=240,
                          theta_i=s.theta_i, phi_i=s.phi_i, theme=s.theme, log=s.log)
        assert first.shape == fig.shape
        assert (np.asarray(first) != np.asarray(fig)).any(axis=2).mean() > 0.01, view
        # A scene of that first BRDF alone is that render (the scene's
        # light and display options are used, not bv's defaults).
        alone = bv.Scene(s.models[:1], theta_i=s.theta_i, phi_i=s.phi_i, log=s.log)
        np.testing.assert_array_equal(bv.render(alone, view=view, width=320, height=240), first)
    # Options given to render override the scene's.
    a = bv.render(s, view="polar", width=320, height=240)
    b = bv.render(s, view="polar", width=320, height=240, theta_i=10)
    assert (np.asarray(a) != np.asarray(b)).any()
    with pytest.raises(ValueError, match="view"):
        bv.render(s, view="nope")
    with pytest.raises(ValueError):
        bv.render(s, theta_i=float("nan"))


def test_docs_and_stub_cover_scenes():
    for f in [bv.Scene, bv.Scene.load, bv.Scene.save, bv.render]:
        assert f.__doc__ and len(f.__doc__) > 60, f
    assert "Scene" in bv.render.__doc__
    # The stub parses and declares every public name with its methods.
    import ast
    import pathlib

    stub = pathlib.Path(bv.__file__).with_suffix(".pyi")
    tree = ast.parse(stub.read_text())
    top = {n.name: n for n in tree.body if isinstance(n, (ast.ClassDef, ast.FunctionDef))}
    for name in bv.__all__:
        assert name in top, name
    scene = {n.name for n in top["Scene"].body if isinstance(n, ast.FunctionDef)}
    public = {k for k in vars(bv.Scene) if not k.startswith("_")}
    assert public <= scene, public - scene
    assert "Scene" in ast.unparse(top["render"].args)
