"""A trial: one (scenario, method, seed) run of a batch, and the directory its results go to."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Trial:
    """One run of a batch."""

    scenario: str  # as given: an embedded name or a YAML path
    scenario_name: str  # the scenario's own name, for directories and tables
    method: str
    seed: int

    @property
    def key(self) -> str:
        """The run's directory name."""
        return f"{self.scenario_name}-{self.method}-{self.seed}"
