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

class _Result(dict[str, Any]):
    """A dict whose keys are also attributes (r.x == r["x"]), as scipy.optimize.OptimizeResult."""
    def __getattr__(self, name: str) -> Any: ...

class OptimizeResult(_Result):
    x: FloatArray  # the best design [Hz, s], in the order of `names`
    fun: float  # its objective (the optimiser's units: mean I_r in 1e-7 kg m; objective_label)
    names: list[str]
    constraints: FloatArray  # g(x), feasible when <= 0
    constraint_names: list[str]
    feasible: bool
    maxcv: float
    metrics: dict[str, float]
    success: bool
    reason: str
    message: str
    nfev: int
    archive_hits: int
    failed_evaluations: int
    gradient_evaluations: int
    wall_time_s: float
    algorithm: str
    problem_id: str
    objective_label: str
    x0: FloatArray
    profile: Optional[dict[str, Any]]
    archive: Optional[str]  # out/archive.sqlite, or None (in memory)
    out: Optional[str]
    history: dict[str, Any]  # x (nfev, d), objective, max_violation, best_feasible, ok, feasible, ... arrays
    validation: Optional[dict[str, Any]]

class SweepResult(_Result):
    method: str
    names: list[str]
    swept: list[str]
    x: FloatArray  # (points, variables) [Hz, s]
    unit: FloatArray  # (points, swept) in [0, 1]
    objective: FloatArray
    objective_hw95: FloatArray
    objective_label: str
    constraints: FloatArray  # (points, constraints)
    constraint_names: list[str]
    max_violation: FloatArray
    ok: npt.NDArray[np.bool_]
    feasible: npt.NDArray[np.bool_]
    from_archive: npt.NDArray[np.bool_]
    metrics: dict[str, FloatArray]
    wall_time_s: FloatArray
    message: list[str]
    best: Optional[int]
    computed: int
    archive_hits: int
    failed: int
    problem_id: str
    archive: Optional[str]
    out: Optional[str]

class ParetoResult(_Result):
    max_startup_time_s: FloatArray  # the bounds, ascending [s]
    startup_time_s: FloatArray
    names: list[str]
    x: FloatArray  # (bounds, variables)
    objective: FloatArray
    objective_hw95: FloatArray
    objective_label: str
    out_of_sample_objective: FloatArray
    out_of_sample_hw95: FloatArray
    pct_mi: FloatArray
    out_of_sample_pct_mi: FloatArray
    feasible: npt.NDArray[np.bool_]
    dominated: npt.NDArray[np.bool_]
    front: npt.NDArray[np.bool_]
    evaluations: npt.NDArray[np.int_]
    starts: npt.NDArray[np.int_]
    kept_start: list[str]
    reason: list[str]
    problem_ids: list[str]
    report_profile: dict[str, Any]
    archive: Optional[str]
    out: Optional[str]

def optimize(
    config: Config,
    *,
    max_evaluations: Optional[int] = None,
    out: Optional[Union[str, os.PathLike]] = None,
    threads: Optional[int] = None,
    seed: Optional[int] = None,
    runs: Optional[int] = None,
    validate: bool = True,
) -> OptimizeResult:
    """As `abuopt optimize`: the best design x [Hz, s], fun (mean I_r in 1e-7 kg m), constraints, nfev, archive."""

def sweep(
    config: Config,
    *,
    out: Optional[Union[str, os.PathLike]] = None,
    threads: Optional[int] = None,
    seed: Optional[int] = None,
    runs: Optional[int] = None,
) -> SweepResult:
    """As `abuopt sweep`: one row per point (x, objective, constraints, feasible, metrics)."""

def pareto(
    config: Config,
    *,
    out: Optional[Union[str, os.PathLike]] = None,
    threads: Optional[int] = None,
    seed: Optional[int] = None,
    runs: Optional[int] = None,
    max_evaluations: Optional[int] = None,
    validate: bool = True,
) -> ParetoResult:
    """As `abuopt pareto`: one row per bound on the startup time; `front` marks the Pareto front."""
