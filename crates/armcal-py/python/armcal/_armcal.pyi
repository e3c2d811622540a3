# Type stubs of the native module armcal._armcal (hand-written; tests/test_stubs.py checks
# that every public class, method and function of the module has its entry here, and no more).
# Units: joint values rad (mm for a prismatic joint), lengths mm, angles rad.

from os import PathLike
from typing import Any, Callable, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

ArrayLike = npt.ArrayLike
F64 = npt.NDArray[np.float64]
Progress = Callable[[str, dict[str, Any]], Any]
Params = Union[None, "Estimate", ArrayLike]

__version__: str

class ArmcalError(ValueError): ...

class Cell:
    @classmethod
    def load(cls, name_or_path: str) -> Cell: ...
    @classmethod
    def from_toml(cls, text: str) -> Cell: ...
    @property
    def name(self) -> str: ...
    @property
    def dof(self) -> int: ...
    @property
    def joints(self) -> list[str]: ...
    def joint_limits(self) -> tuple[F64, F64]: ...
    def nominal(self) -> F64: ...
    def working_poses(self) -> F64: ...
    def parameters(self) -> list[dict[str, Any]]: ...
    @classmethod
    def _restore(cls, kind: str, arg: str) -> Cell: ...

class _Record:
    def to_json(self) -> str: ...
    @classmethod
    def from_json(cls, text: str) -> Any: ...
    def to_dict(self) -> Any: ...

class Dataset(_Record):
    @property
    def q(self) -> F64: ...
    @property
    def ids(self) -> list[str]: ...
    @property
    def measured(self) -> F64: ...
    @property
    def config(self) -> list[int]: ...
    def __len__(self) -> int: ...

class Estimate(_Record):
    @property
    def params(self) -> F64: ...
    @property
    def names(self) -> list[str]: ...
    @property
    def free(self) -> list[str]: ...
    @property
    def sigma(self) -> F64: ...
    @property
    def cov(self) -> F64: ...
    @property
    def tcp_cov(self) -> F64: ...
    @property
    def status(self) -> str: ...
    @property
    def converged(self) -> bool: ...
    @property
    def residuals(self) -> F64: ...
    @property
    def validation(self) -> Optional[dict[str, Any]]: ...

class Design(_Record):
    @property
    def q(self) -> F64: ...
    @property
    def value(self) -> Optional[float]: ...
    @property
    def status(self) -> Optional[str]: ...
    @property
    def sigma(self) -> F64: ...
    @property
    def tcp_cov(self) -> F64: ...

class CampaignState(_Record):
    def next_q(self, cell: Cell) -> F64: ...
    @property
    def next_ids(self) -> list[str]: ...
    @property
    def decision(self) -> str: ...
    @property
    def measured(self) -> int: ...

class DriftCheck(_Record):
    def moved_groups(self) -> list[str]: ...

def fk(cell: Cell, q: ArrayLike, params: Params = None) -> F64: ...
def perturbed_truth(cell: Cell, seed: int = 1) -> F64: ...
def simulate(
    cell: Cell,
    q: ArrayLike,
    truth: Optional[ArrayLike] = None,
    noise: bool = True,
    seed: int = 1,
    ids: Optional[Sequence[str]] = None,
) -> Dataset: ...
def predict(cell: Cell, q: ArrayLike, params: Params = None) -> Dataset: ...
def dataset(
    cell: Cell,
    q: ArrayLike,
    measured: ArrayLike,
    sigma: Optional[ArrayLike] = None,
    ids: Optional[Sequence[str]] = None,
) -> Dataset: ...
def identify(
    cell: Cell,
    q: Union[ArrayLike, Dataset],
    measured: Optional[ArrayLike] = None,
    *,
    sigma: Optional[ArrayLike] = None,
    method: str = "lm",
    robust: Optional[str] = None,
    holdout: float = 0.0,
    seed: int = 1,
    progress: Optional[Progress] = None,
) -> Estimate: ...
def plan(
    cell: Cell,
    n: int = 60,
    *,
    criterion: str = "kpi",
    collisions: bool = True,
    pool: Optional[ArrayLike] = None,
    seed: int = 1,
    starts: int = 2,
    progress: Optional[Progress] = None,
) -> Design: ...
def assess(cell: Cell, q: ArrayLike) -> dict[str, Any]: ...
def compensate(
    cell: Cell, estimate: Estimate, q: ArrayLike, targets: Optional[ArrayLike] = None
) -> dict[str, Any]: ...
def campaign_start(
    cell: Cell,
    *,
    target_sigma_mm: float = 0.5,
    batch: int = 5,
    budget: Optional[int] = None,
    seed: int = 1,
    progress: Optional[Progress] = None,
) -> CampaignState: ...
def campaign_step(
    cell: Cell,
    state: CampaignState,
    q: Union[ArrayLike, Dataset],
    measured: Optional[ArrayLike] = None,
    *,
    progress: Optional[Progress] = None,
) -> tuple[CampaignState, Optional[Estimate]]: ...
def check(
    cell: Cell,
    estimate: Estimate,
    q: Union[ArrayLike, Dataset],
    measured: Optional[ArrayLike] = None,
    *,
    alpha: float = 0.05,
) -> DriftCheck: ...
def report(
    records: Sequence[Union[Estimate, Design, DriftCheck, CampaignState, str, PathLike[str]]],
    out: Union[str, PathLike[str]],
    *,
    title: str = "armcal report",
    accept_unconverged: bool = False,
) -> str: ...
def read_record(path: Union[str, PathLike[str]]) -> Union[Estimate, Design, CampaignState, DriftCheck]: ...
def fleet_task(
    cell: Cell,
    seed: int,
    *,
    poses: int = 60,
    check_poses: int = 20,
    collisions: bool = False,
    out: Optional[Union[str, PathLike[str]]] = None,
) -> dict[str, Any]: ...
def fleet(
    cells: Sequence[Cell],
    *,
    seed: int = 1,
    poses: int = 60,
    check_poses: int = 20,
    collisions: bool = False,
    out: Optional[Union[str, PathLike[str]]] = None,
    progress: Optional[Progress] = None,
) -> list[dict[str, Any]]: ...
