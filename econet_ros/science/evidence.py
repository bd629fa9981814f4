"""What the claims of one study group are judged on, as statistics over runs: window means per
run, their t intervals, paired comparisons (runs pair by run number: run k of every
condition has the same seed and so the same trial starts), per-run joint classifications, the
lesion test; and the two nulls each rule is checked against (random movement in the place of
the normal condition, and every run's generations shuffled in time). ROS-free."""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..config import Config
from ..run_folders import RunData
from . import holding
from .measures import ReachSummary
from .series import Windows, nanmean, per_run, smooth
from .stats import Estimate, Paired, estimate, paired
from .study import ConditionData

LOCK = 10.0            # a joint is locked / dominated when flexion% <= LOCK or >= 100 - LOCK
# The outcomes whose runs split into holding and brushing runs (docs/analysis.md, "Hold or
# brush, per run"): their paired differences are judged on medians (the sign test), since a t
# interval under-covers on such mixtures. Separations per successful trial are one too.
MIXTURES = frozenset({"top_fitness", "top_successes", "top_separations"})


@dataclass
class Evidence:
    """A study group's conditions, the lesion test of its normal runs and the windows. Claims
    read their data only through these methods, which raise ValueError for a condition without
    runs (the claim is then "not measurable")."""

    group: dict[str, ConditionData]
    lesion: list[dict]
    windows: Windows
    _joints: dict = dataclasses.field(default_factory=dict, repr=False)

    @property
    def G(self) -> int:
        return self.windows.G

    def condition(self, name: str) -> ConditionData:
        if name not in self.group or not self.group[name].n_runs:
            raise ValueError(f"no {name} runs")
        return self.group[name]

    def run_config(self, condition: str) -> Config:
        """The settings of the condition's first run (trials, cycles)."""
        return RunData(self.condition(condition).run_dirs[0]).config

    # -- per run ------------------------------------------------------------------------------
    def curve(self, condition: str, column: str) -> np.ndarray:
        """The mean over runs, per generation."""
        return nanmean(per_run(self.condition(condition), column), axis=0)

    def per_run(self, condition: str, column: str, window: slice) -> dict[str, float]:
        """Each run's mean over a generation window, by run folder name."""
        data = self.condition(condition)
        means = nanmean(per_run(data, column)[:, window], axis=1)
        return {path.name: float(m) for path, m in zip(data.run_dirs, means)}

    def per_success(self, condition: str, window: slice) -> dict[str, float]:
        """Each run's separations per successful trial over a window: the window sum of the top
        20's separations over that of their successful trials (holding.per_success, the
        definition a run's holding is judged by)."""
        data = self.condition(condition)
        separations, successes = (per_run(data, c)[:, window]
                                  for c in ("top_separations", "top_successes"))
        return {path.name: holding.per_success(s, k)
                for path, s, k in zip(data.run_dirs, separations, successes)}

    def estimate(self, condition: str, column: str, window: slice) -> Estimate:
        return estimate(list(self.per_run(condition, column, window).values()))

    # -- comparisons --------------------------------------------------------------------------
    @staticmethod
    def paired(a: dict[str, float], b: dict[str, float], mixture: bool = False) -> Paired:
        """a - b over the runs both have, paired by run (mixture: by the median difference)."""
        names = sorted(set(a) & set(b))
        return paired([a[n] for n in names], [b[n] for n in names], mixture)

    def compare(self, a: tuple[str, str, slice], b: tuple[str, str, slice]) -> Paired:
        """(condition, column, window) of a minus that of b, paired by run; by the median
        difference for the outcomes that are mixtures of holding and brushing runs."""
        return self.paired(self.per_run(*a), self.per_run(*b), a[1] in MIXTURES)

    # -- joints and the lesion ----------------------------------------------------------------
    def joints(self, lock: float = LOCK, group: str = "all") -> list[dict]:
        """The normal runs' joint table (joint_table), once per lock threshold and group."""
        if (lock, group) not in self._joints:
            self._joints[lock, group] = joint_table(self.condition("normal"), self.windows,
                                                    lock, group)
        return self._joints[lock, group]

    def reaches(self, kind: str) -> list[ReachSummary]:
        """Reach summaries per normal run, kind "intact", "lesioned" or "vision-lesioned"."""
        if not self.lesion:
            raise ValueError("no normal runs")
        return [run[kind] for run in self.lesion]

    # -- the nulls ----------------------------------------------------------------------------
    def random_as_normal(self) -> "Evidence":
        """The same group with random movement in the normal condition's place (no lesion)."""
        group = dict(self.group)
        group["normal"] = dataclasses.replace(self.condition("random"), name="normal")
        return Evidence(group, [], self.windows)

    def shuffled(self, rng: np.random.Generator) -> "Evidence":
        """Every run's generations in a random order (one order per run, the same for all its
        columns), so nothing that depends on time can hold but by chance (no lesion)."""
        group = {name: _shuffled(data, rng) for name, data in self.group.items()}
        return Evidence(group, [], self.windows)


def _shuffled(data: ConditionData, rng: np.random.Generator) -> ConditionData:
    if not data.n_runs:
        return data
    order = np.array([rng.permutation(data.generations) for _ in range(data.n_runs)])
    take = lambda table: {k: np.take_along_axis(v, order, axis=1)  # noqa: E731
                          for k, v in table.items()}
    return dataclasses.replace(data, metrics=take(data.metrics), behaviour=take(data.behaviour))


# -- per-run joint classification ----------------------------------------------------------
def joint_table(data: ConditionData, windows: Windows, lock: float = LOCK,
                group: str = "all") -> list[dict]:
    """Per run: final-window flexion % and angle of both joints, whether the shoulder is
    locked (flexion <= lock or >= 100 - lock, in the ``group``'s cycles: all econets or the top
    20), in which position and from which generation it first is (first passage of the
    smoothed flexion), and how much the elbow moves."""
    final = windows.final
    columns = (f"{group}_shoulder_flexion", f"{group}_shoulder_angle", "all_elbow_flexion",
               "all_elbow_angle", "all_elbow_moving")
    sf, sa, ef, ea, em = (nanmean(per_run(data, c)[:, final], axis=1) for c in columns)
    full = per_run(data, f"{group}_shoulder_flexion")
    rows = []
    for i, path in enumerate(data.run_dirs):
        locked = bool(np.isfinite(sf[i]) and dominated(sf[i], lock))
        series = smooth(full[i], max(1, windows.G // 20))   # 10-generation running mean
        rows.append({"run": path.name, "shoulder_flexion": sf[i], "shoulder_angle": sa[i],
                     "locked": locked, "position": _position(locked, sa[i]),
                     "lock_generation": first_passage(dominated(series, lock)),
                     "elbow_flexion": ef[i], "elbow_angle": ea[i], "elbow_moving": em[i]})
    return rows


def dominated(flexion, lock: float = LOCK):
    """One muscle of the joint wins on (nearly) every cycle: flexion % <= lock or >= 100 -
    lock."""
    return (flexion <= lock) | (flexion >= 100 - lock)


def first_passage(flags: np.ndarray) -> float:
    """The first generation at which a condition holds; NaN if it never does."""
    hits = np.flatnonzero(np.nan_to_num(flags, nan=0).astype(bool))
    return float(hits[0]) if len(hits) else np.nan


def _position(locked: bool, angle: float) -> str:
    if not locked:
        return "not locked"
    if angle >= 135:
        return "extended"
    return "flexed" if angle <= 45 else "mid-range"
