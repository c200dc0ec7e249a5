"""Type stubs of the Rust extension; the package's public API is in ``poolsim/__init__.py``."""

from typing import Any, Iterator

def run(scenario: str, ask: dict[str, Any]) -> dict[str, Any]: ...
def stream(scenario: str, ask: dict[str, Any], chunk: int) -> Stream: ...
def event_kinds() -> list[str]: ...
def builtins() -> list[tuple[str, str]]: ...
def phold(
    *,
    objects: int = ...,
    events_per_object: int = ...,
    remote: float = ...,
    lookahead: float = ...,
    mean: float = ...,
    seed: int = ...,
    end: float = ...,
    engine: str = ...,
    workers: int | None = ...,
    partitions: int | None = ...,
) -> str: ...

def experiment(
    which: str,
    out: Any,
    *,
    quick: bool = ...,
    seeds: int | None = ...,
    balls: list[int] | None = ...,
    font: Any = ...,
) -> None: ...
def write_xyz(
    path: str,
    frames: list[tuple[Any, ...]],
    lo: tuple[float, float],
    hi: tuple[float, float],
    periodic: bool,
) -> None: ...
def read_xyz(path: str) -> list[dict[str, Any]]: ...

class Stream:
    def __iter__(self) -> Iterator[dict[str, Any]]: ...
    def __next__(self) -> dict[str, Any]: ...
    @property
    def summary(self) -> str | None: ...
    def close(self) -> None: ...
