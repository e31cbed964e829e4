"""`ExecutorConfig`: where a command's independent units of work run (docs/architecture.md §6).

Nested into every command that fans work out (`nbv compare`, `nbv online`), so
`--workers` and `--ray` have one name and one meaning everywhere. Light to
import: Ray is imported only when `--ray` is given.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class ExecutorConfig:
    """How the independent units of a command run: in this process, in local workers, or on Ray."""

    workers: int = 1
    """Local worker processes running the units at once (spawned, each capping torch's and Dr.Jit's
    threads to its share of the cores); 1 runs them one after another in this process. With --ray auto:
    the CPUs of the local Ray instance."""
    ray: str | None = None
    """Run the units as Ray tasks: 'auto' starts a local Ray instance with --workers CPUs, an address
    (HOST:PORT or ray://HOST:PORT) joins a running cluster whose nodes share the output folder."""

    def __post_init__(self) -> None:
        if self.workers < 1:
            raise ValueError(f"workers must be >= 1, got {self.workers}")
        if self.ray is not None and not self.ray.strip():
            raise ValueError("ray must be 'auto' or a cluster address, got an empty string")
        if self.ray is not None and self.ray.strip() != "auto":
            host, colon, port = self.ray.strip().removeprefix("ray://").rpartition(":")
            if not (colon and host and port.isdigit() and 0 < int(port) < 65536):
                raise ValueError(f"--ray must be 'auto', HOST:PORT or ray://HOST:PORT, got {self.ray!r}")
