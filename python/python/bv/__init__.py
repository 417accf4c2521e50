"""bv, the BRDF viewer, from Python.

Models of bv's catalogue (and user ``.brdf`` files, MERL ``.binary`` tables)
evaluated on numpy arrays, sampled, integrated and checked by the same Rust
code as the ``bv`` command line::

    import numpy as np
    import bv

    m = bv.Model("cook-torrance", alpha=0.3, fresnel="conductor", eta=[0.2, 0.92, 1.1])
    wi = np.array([0.0, 0.0, 1.0])                      # one direction broadcasts
    wo = np.array([[0.0, 0.6, 0.8], [0.6, 0.0, 0.8]])
    f = m.eval(wi, wo)                                  # (2, 3) float32, 1/sr per RGB channel
    rho, err = m.albedo([0, 30, 60])                    # ρhd with its error estimate
    report = m.check()                                  # the dict of `bv check --json`
    r = bv.fit(bv.Model("ward"), to=m)                  # Ward's best fit to m (as `bv fit`)
    scene = bv.Scene([m, bv.Model("lambert")], theta_i=30)
    scene.save("two.toml")                              # a scene file (bv --scene two.toml)
    fig = bv.render(bv.Scene.load("two.toml"), view="polar")  # (H, W, 4) uint8, shown by Jupyter

Conventions (as everywhere in bv): the normal is +z, the tangent +x; ``wi``
(towards the light) and ``wo`` (towards the viewer) point away from the
surface; f(wi, wo) is given without the cosine factor, in 1/sr, per linear-RGB
channel. Directions must be unit length within 1e-3 (they are normalised).
Every error (an unknown model or parameter, a value out of range, a wrong
array shape, a NaN direction, a missing file) is a ``ValueError`` carrying
bv's message.
"""

from __future__ import annotations

import json
import os
import struct
import warnings
import zlib
from typing import Any, Dict, List, Sequence, Tuple, Union

import numpy as np

from . import _native

__all__ = ["Figure", "FitResult", "Model", "Scene", "fit", "models", "render"]

ArrayLike = Union[np.ndarray, Sequence[float], Sequence[Sequence[float]]]


def models() -> List[Dict[str, Any]]:
    """The model catalogue, as ``bv models --json`` prints it.

    One dict per model: ``id``, ``name``, ``summary``, ``citation`` and
    ``params`` (each parameter's id, kind, range, default, unit and the
    condition under which it applies).
    """
    return json.loads(_native.models_json())


def _directions(name: str, a: ArrayLike) -> np.ndarray:
    """``a`` as a C-contiguous float64 ``(N, 3)`` array (a ``(3,)`` one
    becomes ``(1, 3)``, which broadcasts)."""
    try:
        arr = np.ascontiguousarray(a, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise ValueError(f"{name} must be an array of directions: {e}") from None
    if arr.ndim == 1:
        arr = arr.reshape(1, -1)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise ValueError(f"{name} must have shape (N, 3) or (3,), found {np.shape(a)}")
    return arr


class Model:
    """A BRDF of bv's catalogue, a user ``.brdf`` file or a MERL table, with
    its parameters.

    ``Model("cook-torrance", alpha=0.3, fresnel="conductor", eta=[0.2, 0.92, 1.1])``
    builds a catalogue model (``bv.models()`` lists them with every
    parameter's range and default; unset parameters keep their defaults, a
    colour is three numbers or one for grey, a choice is its name).
    ``Model("retro.brdf")`` compiles a user file; ``Model("gold.binary")``
    loads a data file with the catalogue model that reads its format (here
    MERL, as ``Model("merl", path="gold.binary")``). The parameters
    are validated as the command line validates them: an unknown model or
    parameter, a value out of range or a file that cannot be read raises
    ``ValueError`` with bv's message.
    """

    def __init__(self, model: str, **params: Any) -> None:
        if not isinstance(model, (str, os.PathLike)):
            raise ValueError(f"model must be a model id or a path, found {model!r}")
        model = os.fspath(model)
        try:
            text = json.dumps(
                {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in params.items()},
                allow_nan=False,
            )
        except (TypeError, ValueError) as e:
            raise ValueError(f"parameters of {model}: {e}") from None
        self._m = _native.Model(model, text)

    @property
    def id(self) -> str:
        """The model id (for a user file, the id its path registered)."""
        return self._m.id

    @property
    def params(self) -> Dict[str, Any]:
        """Every parameter's value, defaults filled in."""
        return json.loads(self._m.params_json())

    @property
    def transmits(self) -> bool:
        """Whether the model scatters below the surface (a BSDF)."""
        return self._m.transmits

    def __repr__(self) -> str:
        return f"bv.Model({self.id!r}, **{self.params!r})"

    def eval(self, wi: ArrayLike, wo: ArrayLike, precision: str = "f32") -> np.ndarray:
        """f(wi, wo) per linear-RGB channel, 1/sr, without the cosine.

        ``wi`` and ``wo`` are ``(N, 3)`` arrays (or one ``(3,)`` direction,
        which broadcasts against the other). ``precision="f32"`` (default)
        evaluates on all cores with the GIL released through bv's f32 SIMD
        batch kernels (held to the f64 code within 1e-4 relative or 1e-6
        absolute by bv's parity tests) and returns float32;
        ``precision="f64"`` uses the f64 reference, what ``bv eval``
        answers, and returns float64. Returns ``(N, 3)``.
        """
        if precision not in ("f32", "f64"):
            raise ValueError(f'precision={precision!r}: expected "f32" or "f64"')
        return self._m.eval(_directions("wi", wi), _directions("wo", wo), precision == "f64")

    def pdf(self, wi: ArrayLike, wo: ArrayLike) -> np.ndarray:
        """The solid-angle density (1/sr) with which :meth:`sample` draws
        ``wo`` for light from ``wi``; ``(N,)`` float64."""
        return self._m.pdf(_directions("wi", wi), _directions("wo", wo))

    def sample(
        self, wi: ArrayLike, u: ArrayLike
    ) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Importance-samples outgoing directions.

        ``wi`` is ``(N, 3)`` (or one direction), ``u`` ``(N, 2)`` uniform
        points in [0, 1)². Returns ``(wo, weight, pdf)``: ``wo`` ``(N, 3)``,
        ``weight`` ``(N, 3)`` = f(wi, wo) |cos θo| / pdf (the Monte Carlo
        weight) and ``pdf`` ``(N,)``. Where the model draws no direction,
        ``wo`` is NaN and weight and pdf are 0. Delta lobes (``mirror``,
        ``glass``) are not sampled here: their f is zero at every finite
        pair (:meth:`albedo` includes their weights).
        """
        try:
            uu = np.ascontiguousarray(u, dtype=np.float64)
        except (TypeError, ValueError) as e:
            raise ValueError(f"u must be an array of points: {e}") from None
        if uu.ndim == 1:
            uu = uu.reshape(1, -1)
        if uu.ndim != 2 or uu.shape[1] != 2:
            raise ValueError(f"u must have shape (N, 2), found {np.shape(u)}")
        return self._m.sample(_directions("wi", wi), uu)

    def albedo(
        self, theta_i: Union[float, ArrayLike], phi_i: float = 0.0
    ) -> Tuple[np.ndarray, np.ndarray]:
        """The directional albedo ρhd(θi) = ∫ f cos θo dωo (plus delta
        lobes' weights) at each θi, **in degrees** (as on bv's command
        line), and azimuth ``phi_i`` (degrees).

        Returns ``(values, errors)``, each ``(N, 3)`` float64: deterministic
        Gauss–Kronrod quadrature with its error estimate for analytic models,
        Monte Carlo with one standard error for measured ones (the estimators
        of ``bv slice --curve albedo`` and the albedo view).
        """
        t = np.atleast_1d(np.asarray(theta_i, dtype=np.float64))
        if t.ndim != 1:
            raise ValueError(f"theta_i must be a number or a 1-D array, found shape {t.shape}")
        try:
            phi = float(phi_i)
        except (TypeError, ValueError) as e:
            raise ValueError(f"phi_i must be a number: {e}") from None
        return self._m.albedo(np.ascontiguousarray(t), phi)

    def check(self, albedo: str = "auto") -> Dict[str, Any]:
        """The properties of the model (positivity, reciprocity, isotropy,
        energy, D normalisation), each with its sample or quadrature count
        and error, beside what the model claims: the dict ``bv check --json``
        prints (``albedo``: ``"auto"``, ``"quadrature"`` or
        ``"monte-carlo"``, as ``--albedo``)."""
        return json.loads(self._m.check_json(albedo))

    def dispatch(self) -> Tuple[bool, str]:
        """``(kernel, isa)``: whether ``eval`` in f32 runs a SIMD batch
        kernel for this model, and on which instruction set (``"scalar"``
        when it falls back to the f64 code lane by lane)."""
        return self._m.dispatch()


class FitResult:
    """What :func:`fit` found: the fitted ``model`` (a :class:`Model`), its
    ``error`` under ``metric`` (and ``initial_error`` at the given values),
    the error per 10° band of θi (``residuals``: dicts with ``theta_i_min``,
    ``theta_i_max``, ``error``, ``samples``), the fitted unknowns (``free``;
    a colour counts three), and the effort (``iterations``, ``evaluations``
    over ``pairs`` direction pairs). ``report`` is the whole dict, as
    ``bv fit --json`` prints it."""

    def __init__(self, model: "Model", report: Dict[str, Any]) -> None:
        self.model = model
        self.report = report
        self.metric: str = report["metric"]
        self.error: float = report["error"]
        self.initial_error: float = report["initial_error"]
        self.residuals: List[Dict[str, Any]] = report["residuals"]
        self.free: List[str] = report["free"]
        self.iterations: int = report["iterations"]
        self.evaluations: int = report["evaluations"]
        self.pairs: int = report["pairs"]

    def __repr__(self) -> str:
        return f"FitResult({self.model!r}, {self.metric} error {self.error:.6g})"


def fit(
    model: "Model",
    to: "Model",
    free: Union[None, str, Sequence[str]] = None,
    metric: str = "ngan",
    starts: int = 4,
) -> FitResult:
    """Fits the parameters ``free`` of ``model`` to the BRDF ``to`` (any
    :class:`Model`: a catalogue model with parameters, a ``.brdf`` file, a
    MERL or RGL file) by Levenberg–Marquardt over bv's fixed set of
    direction pairs, exactly as ``bv fit`` does (bv-core's ``fit`` module).

    ``model``'s own values are the first starting point and the values of
    the parameters that are not free. ``free``: parameter ids (or an alias
    such as ``"alpha"``), as a list or a comma-separated string; default,
    every float and colour parameter that applies. ``metric``: ``"ngan"``
    (Ngan et al. 2005, the cube root of f cos θi) or ``"e2"`` (Löw et al.
    2012, ln(1 + f cos θi)). ``starts``: 1 to 64 deterministic starting
    points. A fit never leaves the parameters' declared ranges.
    """
    if not isinstance(model, Model) or not isinstance(to, Model):
        raise ValueError("fit(model, to): both must be bv.Model objects")
    if isinstance(free, str):
        free = [f.strip() for f in free.split(",") if f.strip()]
    elif free is not None:
        free = [str(f) for f in free]
    try:
        n = int(starts)
    except (TypeError, ValueError) as e:
        raise ValueError(f"starts must be an integer: {e}") from None
    native, report = _native.fit(model._m, to._m, free, str(metric), n)
    return FitResult(_model_of(native), json.loads(report))


def _model_of(native: Any) -> "Model":
    """A :class:`Model` around an already built ``_native.Model``."""
    m = Model.__new__(Model)
    m._m = native
    return m


class Scene:
    """A bv scene: BRDFs (model, parameters, colour, visibility), the
    light's direction, camera and display options; what the viewer's
    File ▸ Save writes and ``bv --scene FILE`` / ``bv render --scene FILE``
    read.

    ``Scene([m1, m2], theta_i=30, log=True)`` makes one from
    :class:`Model` objects (checked as ``bv scene new`` checks its options);
    :meth:`load` reads a scene file and :meth:`save` writes one. ``s1 == s2``
    compares everything a scene file records. :func:`render` draws a
    scene with all its BRDFs.
    """

    def __init__(
        self,
        models: Sequence["Model"] = (),
        theta_i: Union[float, None] = None,
        phi_i: Union[float, None] = None,
        log: bool = False,
        cosine: bool = False,
        theme: Union[str, None] = None,
    ) -> None:
        ms = list(models)
        for m in ms:
            if not isinstance(m, Model):
                raise ValueError(f"models must be bv.Model objects, found {type(m).__name__}")
        if theme not in (None, "light", "dark"):
            raise ValueError(f'theme={theme!r}: expected "light" or "dark"')
        self._s = _native.Scene(
            [m._m for m in ms],
            None if theta_i is None else float(theta_i),
            None if phi_i is None else float(phi_i),
            bool(log),
            bool(cosine),
            theme == "light",
        )

    @classmethod
    def load(cls, path: Union[str, os.PathLike]) -> "Scene":
        """Reads a scene file (relative paths in it are taken from its
        folder). A file bv refuses (missing, not TOML, a bad value, a model
        that cannot be built) raises ``ValueError`` with the message of ``bv
        scene check``; remarks that do not refuse it (unknown keys) are
        issued as ``UserWarning`` and kept in :attr:`warnings`."""
        s = cls.__new__(cls)
        s._s = _native.Scene.load(os.fspath(path))
        for w in s._s.warnings:
            warnings.warn(f"{os.fspath(path)}: {w}", UserWarning, stacklevel=2)
        return s

    def save(self, path: Union[str, os.PathLike]) -> None:
        """Writes the scene file atomically (file paths relative to its
        folder where they lie inside it), as the viewer saves; an error
        (a missing folder, a read-only file) raises ``ValueError``."""
        self._s.save(os.fspath(path))

    def to_toml(self) -> str:
        """The scene file's text."""
        return self._s.to_toml()

    @property
    def brdfs(self) -> List[Dict[str, Any]]:
        """The BRDFs in order: dicts of ``id``, ``params`` (every value),
        ``name`` (a preset's, or None), ``visible`` and ``color`` (sRGB)."""
        return json.loads(self._s.brdfs_json())

    @property
    def models(self) -> List["Model"]:
        """The BRDFs as :class:`Model` objects, in order."""
        return [_model_of(m) for m in self._s.models()]

    @property
    def theta_i(self) -> float:
        """The light's polar angle, degrees."""
        return self._s.theta_i

    @property
    def phi_i(self) -> float:
        """The light's azimuth, degrees."""
        return self._s.phi_i

    @property
    def log(self) -> bool:
        """Whether plots use a logarithmic scale."""
        return self._s.log

    @property
    def cosine(self) -> bool:
        """Whether plots show f · cos θo."""
        return self._s.cosine

    @property
    def theme(self) -> str:
        """``"light"`` or ``"dark"``."""
        return self._s.theme

    @property
    def warnings(self) -> List[str]:
        """What loading remarked on without refusing the file."""
        return self._s.warnings

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Scene):
            return NotImplemented
        return self._s.same_as(other._s)

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        ids = ", ".join(b["id"] for b in self.brdfs)
        return f"<bv.Scene [{ids}] θi={self.theta_i}° φi={self.phi_i}°>"


def _png(rgba: np.ndarray) -> bytes:
    """An (H, W, 4) uint8 array as PNG bytes (8-bit RGBA, no filter)."""
    h, w, _ = rgba.shape

    def chunk(tag: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data))

    raw = b"".join(b"\x00" + np.ascontiguousarray(rgba[y]).tobytes() for y in range(h))
    return (
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 6, 0, 0, 0))
        + chunk(b"IDAT", zlib.compress(raw, 6))
        + chunk(b"IEND", b"")
    )


class Figure(np.ndarray):
    """An ``(H, W, 4)`` uint8 RGBA image drawn by bv: a numpy array (slice
    it, ``plt.imshow`` it) that Jupyter shows as a PNG (``_repr_png_``) and
    :meth:`save` writes as one."""

    def _repr_png_(self) -> bytes:
        return _png(np.asarray(self, dtype=np.uint8))

    def save(self, path: Union[str, os.PathLike]) -> None:
        """Writes the image as a PNG file."""
        with open(path, "wb") as f:
            f.write(self._repr_png_())


def render(
    model: Union[Model, Scene],
    view: str = "lobe3d",
    width: int = 800,
    height: int = 600,
    theta_i: Union[float, None] = None,
    phi_i: Union[float, None] = None,
    theme: Union[str, None] = None,
    log: bool = False,
    cosine: bool = False,
    transparent: bool = False,
    scale: Union[float, None] = None,
) -> Figure:
    """Draws one view of ``model`` as ``bv render --view VIEW`` draws it (the
    viewer's own drawing code, offscreen with wgpu; Mesa's lavapipe on a
    machine without a GPU) and returns it as a :class:`Figure`, an
    ``(height, width, 4)`` uint8 RGBA array.

    ``model`` is a :class:`Model` (drawn alone, with bv's default light and
    display) or a :class:`Scene` (all its BRDFs, its light, theme and display
    options, as ``bv render --scene FILE`` draws its file; the options
    given here override the scene's).

    ``view``: ``lobe3d``, ``polar``, ``cartesian``, ``albedo``, ``fresnel``
    or any view ``bv render --help`` lists. ``theta_i``/``phi_i``: the
    light's direction in degrees. ``theme``: ``"light"`` (dark on white, for
    slides and print) or ``"dark"``. ``log``: a logarithmic scale;
    ``cosine``: show f·cos θo; ``scale``: pixels per point (default width /
    800 within 1..4). Options are checked by ``bv render``'s parser: a bad
    one raises ``ValueError`` with its message.
    """
    if not isinstance(model, (Model, Scene)):
        raise ValueError(f"model must be a bv.Model or a bv.Scene, found {type(model).__name__}")
    args = ["--view", str(view), "--width", str(int(width)), "--height", str(int(height))]
    if theta_i is not None:
        args += ["--theta-i", repr(float(theta_i))]
    if phi_i is not None:
        args += ["--phi-i", repr(float(phi_i))]
    if theme is not None:
        if theme not in ("light", "dark"):
            raise ValueError(f'theme={theme!r}: expected "light" or "dark"')
        args.append("--" + theme)
    if scale is not None:
        args += ["--scale", repr(float(scale))]
    args += [flag for flag, on in (("--log", log), ("--cosine", cosine), ("--transparent", transparent)) if on]
    if isinstance(model, Scene):
        return _native.render_scene(model._s, args).view(Figure)
    return _native.render(model._m, args).view(Figure)
