"""Type stub of the `bv` package (bv, the BRDF viewer, from Python)."""

import os
from typing import Any, Dict, List, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

ArrayLike = Union[npt.ArrayLike, Sequence[float], Sequence[Sequence[float]]]

def models() -> List[Dict[str, Any]]:
    """The model catalogue, as ``bv models --json`` prints it."""

class Model:
    """A BRDF of bv's catalogue, a user ``.brdf`` file or a MERL table, with its parameters."""

    def __init__(self, model: str, **params: Any) -> None: ...
    @property
    def id(self) -> str:
        """The model id."""
    @property
    def params(self) -> Dict[str, Any]:
        """Every parameter's value, defaults filled in."""
    @property
    def transmits(self) -> bool:
        """Whether the model scatters below the surface."""
    def eval(
        self, wi: ArrayLike, wo: ArrayLike, precision: str = "f32"
    ) -> npt.NDArray[np.floating[Any]]:
        """f(wi, wo), (N, 3): float32 through the batch kernels, float64 with precision="f64"."""
    def pdf(self, wi: ArrayLike, wo: ArrayLike) -> npt.NDArray[np.float64]:
        """The density of `sample` at wo, (N,)."""
    def sample(
        self, wi: ArrayLike, u: ArrayLike
    ) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """(wo (N, 3), weight (N, 3), pdf (N,)) for uniform points u (N, 2)."""
    def albedo(
        self, theta_i: Union[float, ArrayLike], phi_i: float = 0.0
    ) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """(ρhd values (N, 3), errors (N, 3)) at θi in degrees."""
    def check(self, albedo: str = "auto") -> Dict[str, Any]:
        """The dict `bv check --json` prints."""
    def dispatch(self) -> Tuple[bool, str]:
        """(kernel, isa) of the f32 evaluation."""

class Scene:
    """A bv scene: BRDFs, light, camera and display options; scene files."""

    def __init__(
        self,
        models: Sequence[Model] = (),
        theta_i: float | None = None,
        phi_i: float | None = None,
        log: bool = False,
        cosine: bool = False,
        theme: str | None = None,
    ) -> None: ...
    @classmethod
    def load(cls, path: Union[str, os.PathLike[str]]) -> Scene:
        """Reads a scene file (ValueError with `bv scene check`'s message)."""
    def save(self, path: Union[str, os.PathLike[str]]) -> None:
        """Writes the scene file atomically."""
    def to_toml(self) -> str:
        """The scene file's text."""
    @property
    def brdfs(self) -> List[Dict[str, Any]]:
        """The BRDFs: id, params, name, visible, color."""
    @property
    def models(self) -> List[Model]:
        """The BRDFs as models."""
    @property
    def theta_i(self) -> float:
        """The light's polar angle, degrees."""
    @property
    def phi_i(self) -> float:
        """The light's azimuth, degrees."""
    @property
    def log(self) -> bool:
        """Logarithmic scale."""
    @property
    def cosine(self) -> bool:
        """Plots show f · cos θo."""
    @property
    def theme(self) -> str:
        """"light" or "dark"."""
    @property
    def warnings(self) -> List[str]:
        """Remarks made while loading."""
    def __eq__(self, other: object) -> bool: ...

class Figure(np.ndarray):
    """An (H, W, 4) uint8 RGBA image drawn by bv, shown as a PNG in Jupyter."""

    def _repr_png_(self) -> bytes: ...
    def save(self, path: Union[str, os.PathLike[str]]) -> None:
        """Writes the image as a PNG file."""

def render(
    model: Union[Model, Scene],
    view: str = "lobe3d",
    width: int = 800,
    height: int = 600,
    theta_i: float | None = None,
    phi_i: float | None = None,
    theme: str | None = None,
    log: bool = False,
    cosine: bool = False,
    transparent: bool = False,
    scale: float | None = None,
) -> Figure:
    """One view of a model, or of a whole scene, as `bv render --view VIEW` draws it."""


class FitResult:
    """What :func:`fit` found (see ``bv.fit``)."""

    model: Model
    report: Dict[str, Any]
    metric: str
    error: float
    initial_error: float
    residuals: List[Dict[str, Any]]
    free: List[str]
    iterations: int
    evaluations: int
    pairs: int
    def __init__(self, model: Model, report: Dict[str, Any]) -> None: ...

def fit(
    model: Model,
    to: Model,
    free: Union[None, str, Sequence[str]] = ...,
    metric: str = ...,
    starts: int = ...,
) -> FitResult:
    """Fits the parameters ``free`` of ``model`` to ``to`` as ``bv fit`` does."""
    ...
