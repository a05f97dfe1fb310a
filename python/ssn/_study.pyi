from typing import Any, Mapping, Optional, Sequence
from concurrent.futures import Executor

from ._ssn import Scene, Value

class StudyRecords(list[dict[str, Any]]):
    run: str
    keys: list[str]
    def columns(self) -> list[tuple[str, list[Any]]]: ...
    def table(self) -> Any: ...
    def to_csv(self, path: str) -> None: ...

def run_case(scene: Scene, index: int, values: Mapping[str, Value], run: str = "solve") -> dict[str, Any]: ...
def run_cases(
    scene: Scene, numbered: Sequence[tuple[int, Mapping[str, Value]]], run: str = "solve"
) -> list[dict[str, Any]]: ...
def study(
    scene: Scene,
    cases: Sequence[Mapping[str, Value]],
    executor: Optional[Executor] = None,
    run: str = "solve",
    batch: int = 1,
) -> StudyRecords: ...
def study_file(scene: Scene, path: str) -> tuple[str, list[dict[str, Value]]]: ...
