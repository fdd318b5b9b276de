"""Rate statistics of message arrival times, as ``ros2 topic hz`` reports them."""

from __future__ import annotations

import dataclasses
import math

# --- ros2 topic hz ----------------------------------------------------------------------

@dataclasses.dataclass(frozen=True)
class RateStatistics:
    """The publishing rate of a topic, as ``ros2 topic hz`` reports it.

    Attributes:
        rate: average rate in Hz (1 / mean period).
        min_period, max_period: shortest and longest time between two messages, seconds.
        std_dev: standard deviation of the periods, seconds.
        samples: number of periods measured (what ros2 prints as "window").
    """

    rate: float
    min_period: float
    max_period: float
    std_dev: float
    samples: int

    def __str__(self) -> str:
        return (f"average rate: {self.rate:.3f}\n\tmin: {self.min_period:.3f}s "
                f"max: {self.max_period:.3f}s std dev: {self.std_dev:.5f}s "
                f"window: {self.samples}")


def rate_statistics(times, window: int | None = None) -> RateStatistics:
    """Rate statistics of arrival times.

    Args:
        times: arrival times in seconds, in order of arrival (1-D array-like).
        window: use only the last ``window`` periods; None uses all.

    Returns:
        The statistics of the periods between consecutive arrivals.

    Raises:
        ValueError: fewer than two times, or times that go backwards.
    """
    import numpy as np  # here, not at the top: graph imports this module, and most ros2 verbs need no numpy

    times = np.asarray(times, dtype=float)
    if times.ndim != 1 or times.size < 2:
        raise ValueError(f"Need at least two arrival times to measure a rate, got {times.size}: "
                         "measure for longer, or check that the topic is published")
    periods = np.diff(times)
    if np.any(periods < 0):
        raise ValueError("Arrival times must not decrease: pass them in order of arrival")
    if window is not None:
        periods = periods[-window:]
    mean = float(periods.mean())
    return RateStatistics(rate=1.0 / mean if mean > 0 else math.inf,
                          min_period=float(periods.min()), max_period=float(periods.max()),
                          std_dev=float(periods.std()), samples=int(periods.size))
