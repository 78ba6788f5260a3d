# Type stubs of the compiled module abuopt (python/src/*.cpp; docs/python.md), installed beside it.
# Units: SI (imbalances in kg m, angles in rad, frequencies in Hz, times in s, amplitudes in mm);
# the optimisation problem's and the archive's values are the optimiser's (mean I_r in 1e-7 kg m).
import os
from typing import Any, Mapping, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

__version__: str
__git_commit__: str

Config = Union[str, os.PathLike, Mapping[str, Any]]
FloatArray = npt.NDArray[np.float64]

class ConfigError(ValueError): ...

def simulate(config: Config, *, beta0: Sequence[float]) -> dict[str, Any]:
    """One startup from beta0 [rad]; beta0/beta_final arrays, residual_imbalance[_x] in kg m."""

def montecarlo(
    config: Config,
    *,
    runs: Optional[int] = None,
    design: Optional[str] = None,
    seed: Optional[int] = None,
    threads: Optional[int] = None,
) -> dict[str, Any]:
    """Monte Carlo over initial ball angles: a dict of arrays, one entry per run (kg m), and 'summary'."""

def equilibrium_set(
    config: Config, freq: float, *, grid: int = 128, other_angles: Sequence[float] = ...
) -> dict[str, Any]:
    """The equilibrium set at constant speed freq [Hz]: beta (grid,), amplitude_mm and in_set (grid, grid)."""

class StartupProfileProblem:
    def __init__(
        self,
        config: Config,
        *,
        runs: Optional[int] = None,
        design: Optional[str] = None,
        seed: Optional[int] = None,
        threads: Optional[int] = None,
    ) -> None: ...
    def evaluate(self, x: Sequence[float]) -> dict[str, Any]:
        """objective, constraints (array, feasible <= 0), metrics, ok, message."""
    @property
    def names(self) -> list[str]: ...
    @property
    def bounds(self) -> list[tuple[float, float]]: ...
    @property
    def scales(self) -> FloatArray: ...
    @property
    def x0(self) -> FloatArray: ...
    @property
    def constraint_names(self) -> list[str]: ...
    @property
    def identity(self) -> str: ...
    @property
    def evaluations(self) -> int: ...
    def startup_time_s(self, x: Sequence[float]) -> float: ...

class BatchProblem:
    """A design problem as a batch function: evaluate(X) with X an (n, d) array (problem_bindings.cpp)."""
    def __init__(
        self,
        config: Config,
        *,
        runs: Optional[int] = None,
        seed: Optional[int] = None,
        threads: Optional[int] = None,
        batch_threads: int = 1,
    ) -> None: ...
    @staticmethod
    def benchmark(name: str) -> "BatchProblem": ...
    def evaluate(self, X: npt.ArrayLike) -> dict[str, Any]:
        """objective (n,), inequality (n, m_i), equality (n, m_e), max_violation (n,), ok (n,), message."""
    def __call__(self, X: npt.ArrayLike) -> dict[str, Any]: ...
    def validate(self, X: npt.ArrayLike) -> dict[str, Any]:
        """Out of sample (startup problem only): objective, max_violation, ok per row."""
    @property
    def name(self) -> str: ...
    @property
    def names(self) -> list[str]: ...
    @property
    def lower(self) -> FloatArray: ...
    @property
    def upper(self) -> FloatArray: ...
    @property
    def x0(self) -> list[float]: ...
    @property
    def inequality_names(self) -> list[str]: ...
    @property
    def equality_names(self) -> list[str]: ...
    @property
    def best_known(self) -> Optional[float]: ...
    @property
    def identity(self) -> str: ...
    @property
    def evaluations(self) -> int: ...

class Archive:
    def __init__(self, path: str, *, tolerance: float = 1e-6) -> None: ...
    @property
    def path(self) -> str: ...
    def problems(self) -> list[dict[str, Any]]: ...
    def evaluations(self, problem: str = "", *, where: Sequence[str] = ()) -> dict[str, Any]: ...
    def history(self, problem: str = "", *, where: Sequence[str] = ()) -> dict[str, Any]: ...
    def best(self, problem: str = "", *, where: Sequence[str] = ()) -> Optional[dict[str, Any]]: ...
    def evaluation(self, id: int, problem: str = "") -> dict[str, Any]: ...
