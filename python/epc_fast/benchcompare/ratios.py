"""The candidate/baseline time ratio of one workload from paired rounds, its confidence
interval, and the verdict.

Each round times the baseline and the candidate back to back, so that both meet the same
machine: the round's ratio cancels what drifts over seconds (another process's load, clock
speed, a neighbour's compile). The estimate is the 10%-trimmed mean of the rounds' log ratios
(a round hit by a burst of load on one side only is an outlier, and trimming keeps one or two
from moving the estimate), and its 95% interval a percentile bootstrap of that statistic over
the blocks of rounds (each block run by its own pair of processes) and the rounds within them,
with a fixed seed so that the same times give the same interval.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Share of the rounds' log ratios cut from each end before averaging.
TRIM = 0.1
#: Bootstrap resamples, and the interval's confidence.
RESAMPLES = 4000
CONFIDENCE = 0.95
SEED = 42


def trimmed_mean(values: np.ndarray, trim: float = TRIM) -> np.ndarray:
    """Mean over the last axis after cutting ``floor(trim * n)`` values from each end."""
    values = np.sort(values, axis=-1)
    n = values.shape[-1]
    cut = int(trim * n)
    return values[..., cut:n - cut].mean(axis=-1)


@dataclass(frozen=True)
class Ratio:
    """Candidate/baseline time ratio of one workload: estimate, 95% interval (``low``,
    ``high``) and rounds; above 1 the candidate is slower."""

    estimate: float
    low: float
    high: float
    rounds: int

    def verdict(self, threshold: float) -> str:
        """``"slower"``: the whole interval is above 1 + threshold, a slowdown beyond the
        threshold is significant (the comparison fails); ``"faster"``: the whole interval is
        below 1 / (1 + threshold); ``"unclear"``: the interval reaches past 1 + threshold but
        not wholly (too few rounds or too noisy a machine to tell); else ``"same"``."""
        if self.low > 1 + threshold:
            return "slower"
        if self.high < 1 / (1 + threshold):
            return "faster"
        if self.high > 1 + threshold:
            return "unclear"
        return "same"


def paired_ratio(baseline_s, candidate_s, blocks=None) -> Ratio:
    """The ratio of paired per-round times (two sequences of equal length, at least 3).
    ``blocks`` gives each round's block of worker processes (default: one block); the
    bootstrap resamples blocks, then rounds within each, so that a difference that lasts as
    long as a process widens the interval as it should."""
    baseline_s = np.asarray(baseline_s, dtype=float)
    candidate_s = np.asarray(candidate_s, dtype=float)
    if baseline_s.shape != candidate_s.shape or baseline_s.ndim != 1 or baseline_s.size < 3:
        raise ValueError(f"paired times: expected two sequences of the same length >= 3, got "
                         f"{baseline_s.shape} and {candidate_s.shape}")
    if not (np.all(baseline_s > 0) and np.all(candidate_s > 0)):
        raise ValueError("paired times: every time must be positive")
    blocks = np.zeros(baseline_s.size, int) if blocks is None else np.asarray(blocks)
    if blocks.shape != baseline_s.shape:
        raise ValueError(f"paired times: blocks has shape {blocks.shape}, expected "
                         f"{baseline_s.shape}")
    logs = np.log(candidate_s / baseline_s)
    groups = [logs[blocks == b] for b in np.unique(blocks)]
    rng = np.random.default_rng(SEED)
    picked = rng.integers(0, len(groups), size=(RESAMPLES, len(groups)))
    boot = np.empty(RESAMPLES)
    for i in range(RESAMPLES):
        values = [g[rng.integers(0, g.size, g.size)] for g in (groups[j] for j in picked[i])]
        boot[i] = trimmed_mean(np.concatenate(values))
    tail = (1 - CONFIDENCE) / 2
    low, high = np.quantile(boot, [tail, 1 - tail])
    return Ratio(float(np.exp(trimmed_mean(logs))), float(np.exp(low)), float(np.exp(high)),
                 int(logs.size))
