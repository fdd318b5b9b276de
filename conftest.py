"""Test-wide set-up: every test run gets a ROS domain of its own and the 'under test' flag.

Both are set in os.environ before any test runs, so nodes started in-process, node processes
and notebook kernels (nbmake) all inherit them.
"""

import os

import pytest

from course_lib import rosenv

_reservation = rosenv.reserve_domain_id()
os.environ["ROS_DOMAIN_ID"] = str(_reservation.domain_id)
os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
os.environ.pop("ROS_LOCALHOST_ONLY", None)
os.environ["COURSE_LIB_UNDER_TEST"] = "1"


@pytest.fixture
def domain_id():
    """A ROS domain id reserved for one test, for tests that need traffic nobody else sees."""
    with rosenv.reserve_domain_id() as reservation:
        yield reservation.domain_id
