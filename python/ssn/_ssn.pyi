"""Type stubs of the native module ``ssn._ssn`` (re-exported by ``ssn``)."""

from os import PathLike
from typing import Any, Mapping, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

from ._termination import Termination

Value = Union[bool, int, float, str, Sequence["Value"]]
Path = Union[str, PathLike[str]]

class Scene:
    """A scene: what ``ssn`` reads from a scene file, with the values set by
    ``with_values``. Immutable and picklable."""

    @staticmethod
    def from_file(path: Path) -> Scene:
        """Reads a scene file (the keys, defaults and errors of ``ssn``)."""
    @staticmethod
    def from_toml(text: str, path: Path = "<string>") -> Scene:
        """A scene from TOML text; ``path`` names it in messages."""
    @staticmethod
    def rod(
        elements: int = 20,
        amplitude: float = 0.04,
        gap: Optional[float] = 0.5,
        mass: str = "consistent",
        zeta: Optional[float] = 0.01,
        omega_ratio: float = 1.0,
        values: Optional[Mapping[str, Value]] = None,
    ) -> Scene:
        """The built-in finite-element rod of the paper (a tip stop at ``gap``; None: no
        contact); any other scene key in ``values``."""
    @staticmethod
    def from_matrices(
        mass: Any,
        stiffness: Any,
        load: Any,
        contacts: Optional[Sequence[Any]] = None,
        damping: Any = None,
        values: Optional[Mapping[str, Value]] = None,
    ) -> Scene:
        """A structure of your own from numpy arrays or scipy.sparse matrices (real and
        finite; ``load`` a vector of length N); contacts as ``(dof, gap[, direction])`` with
        a 0-based integer dof, or ``{"row": G_row, "gap": g}`` with a row of G over one or
        several dofs (``"dof"`` instead of ``"row"``; ``"friction": mu`` with
        ``"tangent": T_row`` adds Coulomb friction; other keys are refused); other scene
        keys (``damping.zeta``, ``forcing.amplitude``, ``solver.harmonics``, ``output.dof``
        (1-based), ...) in ``values``. Refusals are ``SceneError`` (``SceneTypeError`` for a
        wrong type) naming the argument, the contact by its 0-based index and entries
        0-based."""
    def with_values(self, values: Mapping[str, Value]) -> Scene:
        """A copy with scene keys set (the keys of ``ssn solve --set``)."""
    @property
    def values(self) -> dict[str, Value]:
        """The scene keys set on this scene."""
    @property
    def path(self) -> str:
        """The scene's file (``<rod>``, ``<matrices>``, ``<string>`` for scenes made here)."""
    @property
    def text(self) -> str:
        """The TOML text as written (before ``values``)."""
    @property
    def title(self) -> Optional[str]:
        """The scene's title."""

class Solution:
    """One periodic response; ``to_dict()`` is the JSON of ``ssn solve --json``."""

    converged: bool
    termination: str
    termination_kind: Termination
    iterations: int
    residual_norm: Optional[float]
    omega: float
    observed_dof: int
    times: npt.NDArray[np.float64]
    displacement: npt.NDArray[np.float64]
    contact_forces: npt.NDArray[np.float64]
    state: npt.NDArray[np.float64]
    contacts: list[dict[str, Any]]
    friction: list[dict[str, Any]]
    blade_amplitudes: Optional[npt.NDArray[np.float64]]
    def blade_displacement(self, blade: int) -> npt.NDArray[np.float64]: ...
    def to_dict(self) -> dict[str, Any]: ...

class FrequencyResponse:
    """A frequency response; ``to_dict()`` is the JSON of ``ssn sweep --json``."""

    converged: bool
    omega: npt.NDArray[np.float64]
    omega_ratio: npt.NDArray[np.float64]
    tip_max: npt.NDArray[np.float64]
    tip_min: npt.NDArray[np.float64]
    amplitude: npt.NDArray[np.float64]
    stable: npt.NDArray[np.float64]
    floquet_max_abs: npt.NDArray[np.float64]
    states: npt.NDArray[np.float64]
    folds: list[float]
    def to_dict(self) -> dict[str, Any]: ...
    def __len__(self) -> int: ...

class SolutionSet:
    """Every periodic solution at one frequency; ``to_dict()`` is the JSON of
    ``ssn solutions --json``."""

    converged: bool
    solutions: list[dict[str, Any]]
    times: npt.NDArray[np.float64]
    displacements: npt.NDArray[np.float64]
    def to_dict(self) -> dict[str, Any]: ...
    def __len__(self) -> int: ...

class Stability:
    """The Floquet stability of the solution at the scene's frequency."""

    converged: bool
    stable: Optional[bool]
    floquet_max_abs: Optional[float]
    multipliers: npt.NDArray[np.complex128]
    def to_dict(self) -> dict[str, Any]: ...

class Model:
    @staticmethod
    def from_scene(scene: Scene) -> Model: ...
    @property
    def dofs(self) -> int: ...
    @property
    def omega_1(self) -> float: ...
    def frequencies(self, count: int) -> list[float]: ...
    def reduce(
        self, method: str = "craig-bampton", modes: int | None = None, cutoff: float | None = None
    ) -> Model: ...

def solve(scene: Scene) -> Solution:
    """``ssn solve``: one periodic response at the scene's frequency (GIL released)."""
def sweep(scene: Scene) -> FrequencyResponse:
    """``ssn sweep``: the frequency response over the scene's ``[sweep]`` (GIL released)."""
def solutions(scene: Scene) -> SolutionSet:
    """``ssn solutions``: every periodic solution at the scene's frequency."""
def modes(scene: Scene) -> dict[str, Any]:
    """``ssn modes``: the backbone of the scene's ``[modes]``, as ``ssn modes --json``."""
def stability(scene: Scene) -> Stability:
    """The Floquet stability of the harmonic-balance solution at the scene's frequency."""
def run_case(scene: Scene, index: int, values: Mapping[str, Value], run: str) -> str:
    """One study case; its record as JSON text."""
def study_table(run: str, keys: Sequence[str], records: str) -> list[tuple[str, list[Any]]]:
    """The table of ``ssn study`` of records given as JSON text."""
def study_csv(run: str, keys: Sequence[str], records: str) -> str:
    """The ``results.csv`` of ``ssn study`` of records given as JSON text."""
def study_cases(scene: Scene, path: Path) -> tuple[str, list[str], list[dict[str, Value]]]:
    """The run kind, keys and cases of a study file."""
def limit_threads(threads: int) -> int:
    """Threads of the linear algebra in this process (1: the calling thread only; 0: every
    core); returns the previous count."""
