from os import PathLike
from typing import Any, Mapping, Optional, Sequence, Set, Tuple, Union, overload, Literal

import numpy as np
import numpy.typing as npt

Positions = Union[Sequence[float], npt.NDArray[np.float64], Mapping[str, float]]
Rows = Union[Sequence[Sequence[float]], npt.NDArray[np.float64]]
Path = Union[str, PathLike[str]]

class Error(Exception):
    """A model, parameters or scene that cannot be loaded or used."""

class Contact:
    link_name: str
    object_name: str
    object_type: str
    triangle: int
    depth: float
    normal: Tuple[float, float, float]
    position: Optional[Tuple[float, float, float]]
    @property
    def link(self) -> str: ...
    @property
    def object(self) -> str: ...
    @property
    def point(self) -> Optional[Tuple[float, float, float]]: ...

class Clearance:
    link_name: str
    object_name: str
    triangle: int
    distance: float
    point_on_link: Tuple[float, float, float]
    point_on_object: Tuple[float, float, float]

class Report:
    in_collision: bool
    contacts: list[Contact]
    clearances: list[Clearance]
    out_of_limits: list[str]
    error: str
    motion: bool
    fraction: Optional[float]
    check_seconds: float
    def to_dict(self) -> dict[str, Any]: ...
    def __bool__(self) -> bool: ...

class Checker:
    def __init__(
        self,
        robot: Optional[Path] = None,
        environment: Optional[Path] = None,
        srdf: Optional[Path] = None,
        thickness: Optional[float] = None,
        side: Optional[Literal["back", "front", "both"]] = None,
        params: Optional[Path] = None,
        clearance_threshold: Optional[float] = None,
    ) -> None: ...
    @staticmethod
    def from_params(path: Path) -> Checker: ...
    @property
    def joint_names(self) -> list[str]: ...
    @property
    def limits(self) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
    def check(self, q: Positions) -> Report: ...
    @overload
    def check_batch(self, q: Rows, depths: Literal[False] = ...) -> npt.NDArray[np.bool_]: ...
    @overload
    def check_batch(self, q: Rows, depths: Literal[True]) -> Tuple[npt.NDArray[np.bool_], npt.NDArray[np.float64]]: ...
    def check_motion(self, q0: Positions, q1: Positions) -> Report: ...
    def check_path(self, q: Rows) -> list[Report]: ...
    def check_motions(self, q0: Rows, q1: Rows) -> Tuple[npt.NDArray[np.bool_], npt.NDArray[np.float64]]: ...
    def clearance(self, q: Positions) -> list[Clearance]: ...
    def _time_rust_checks(self, q: Rows) -> Tuple[float, int]: ...
    def link_poses(self, q: Positions) -> dict[str, npt.NDArray[np.float64]]: ...
    def collision_geometry(self) -> dict[str, list[Tuple[str, Any, npt.NDArray[np.float64]]]]: ...
    def apply_collision_object(self, msg: Mapping[str, Any], q: Optional[Positions] = None) -> None: ...
    def apply_attached_collision_object(self, msg: Mapping[str, Any], q: Optional[Positions] = None) -> None: ...
    @property
    def scene_object_count(self) -> Tuple[int, int]: ...

def areas(vertices: Rows, faces: Any, thickness: float = 0.02, side: Literal["back", "front", "both"] = "back") -> dict[str, npt.NDArray[Any]]: ...

class Scene:
    def __init__(self) -> None: ...
    def add_object(
        self,
        name: str,
        mesh: Any,
        faces: Any = None,
        transform: Any = None,
        thin: bool = True,
        thickness: float = 0.02,
        side: Literal["back", "front", "both"] = "back",
    ) -> None: ...
    def set_transform(self, name: str, transform: Any) -> None: ...
    def remove_object(self, name: str) -> None: ...
    @property
    def names(self) -> list[str]: ...
    @overload
    def in_collision_single(self, shape: Any, transform: Any = None, return_names: Literal[False] = ...) -> bool: ...
    @overload
    def in_collision_single(self, shape: Any, transform: Any = None, *, return_names: Literal[True]) -> Tuple[bool, Set[str]]: ...
    def __len__(self) -> int: ...
