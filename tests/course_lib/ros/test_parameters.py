"""Tests for course_lib.ros.parameters: a running node's parameters through its parameter services."""

import pytest
import yaml
from rcl_interfaces.msg import SetParametersResult
from rclpy.node import Node

from course_lib.ros import discovery, parameters, session


class Tunable(Node):
    """A node with a few parameters whose on-set callback rejects a negative rate."""

    def __init__(self):
        super().__init__("tunable")
        self.declare_parameter("rate", 10.0)
        self.declare_parameter("name", "cam")
        self.declare_parameter("limits.low", 1)
        self.declare_parameter("gains", [1, 2])
        self.add_on_set_parameters_callback(self.check)

    def check(self, changes):
        for change in changes:
            if change.name == "rate" and change.value <= 0:
                return SetParametersResult(successful=False, reason="rate must be positive")
        return SetParametersResult(successful=True)


@pytest.fixture
def tunable(domain_id, monkeypatch):
    monkeypatch.setattr(discovery, "SETTLE_SECONDS", 0.0)
    session.start(domain_id=domain_id)
    try:
        yield session.add_node(Tunable())
    finally:
        session.stop()


def test_names_and_values_of_a_running_node(tunable):
    """names() lists every declared parameter; get() gives Python values."""
    assert parameters.names("/tunable") == ["gains", "limits.low", "name", "rate",
                                            "start_type_description_service", "use_sim_time"]
    assert parameters.names("tunable", prefixes=["limits"]) == ["limits.low"]
    assert parameters.get("/tunable", "rate") == 10.0 and parameters.get("/tunable", "gains") == [1, 2]
    assert parameters.types("/tunable", ["rate", "gains"]) == {"rate": "double", "gains": "integer array"}
    with pytest.raises(LookupError, match="has no parameter 'nope'; it has: gains, limits.low"):
        parameters.get("/tunable", "nope")


def test_set_goes_through_the_nodes_callback(tunable):
    """An accepted value reaches the node; a rejected one leaves it and says why."""
    assert parameters.set("/tunable", "rate", 5.0).successful
    assert tunable.get_parameter("rate").value == 5.0
    refused = parameters.set("/tunable", "rate", -1.0)
    assert (refused.successful, refused.reason) == (False, "rate must be positive")
    assert tunable.get_parameter("rate").value == 5.0
    assert not parameters.set("/tunable", "rate", 5).successful  # an integer for a double


def test_dump_is_a_params_file_that_load_reads_back(tunable, tmp_path):
    """dump() nests dotted names under the node and ros__parameters; load() sets them again."""
    dumped = yaml.safe_load(parameters.dump("/tunable"))
    assert dumped["/tunable"]["ros__parameters"]["limits"] == {"low": 1}
    assert dumped["/tunable"]["ros__parameters"]["name"] == "cam"
    dumped["/tunable"]["ros__parameters"]["name"] = "webcam"
    dumped["/tunable"]["ros__parameters"]["rate"] = -3.0
    path = tmp_path / "tunable.yaml"
    path.write_text(yaml.dump(dumped))
    results = dict(parameters.load("/tunable", path))
    assert results["name"].successful and not results["rate"].successful
    assert tunable.get_parameter("name").value == "webcam"


def test_a_node_that_is_not_there_times_out_with_the_fix(tunable):
    """A node without parameter services is a TimeoutError that says what to check."""
    with pytest.raises(TimeoutError, match="parameter services for node /ghost: is it running"):
        parameters.names("/ghost", timeout=0.3)
