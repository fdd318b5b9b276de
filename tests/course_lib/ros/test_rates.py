"""Tests for course_lib.ros.rates: ros2 topic hz's statistics of arrival times."""

import numpy as np
import pytest

from course_lib.ros import rates


def test_rate_statistics_of_known_arrival_times():
    """Periods 0.1, 0.1, 0.2 s give 7.5 Hz, min 0.1, max 0.2, and a window of 3 periods."""
    stats = rates.rate_statistics([0.0, 0.1, 0.2, 0.4])
    assert stats.rate == pytest.approx(7.5)
    assert (stats.min_period, stats.max_period) == pytest.approx((0.1, 0.2))
    assert stats.std_dev == pytest.approx(np.std([0.1, 0.1, 0.2]))
    assert stats.samples == 3
    assert rates.rate_statistics([0.0, 0.1, 0.2, 0.4], window=1).rate == pytest.approx(5.0)
    with pytest.raises(ValueError, match="at least two"):
        rates.rate_statistics([1.0])
