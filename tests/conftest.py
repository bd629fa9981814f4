"""The suite mirrors the package: core/ (the model, evolution, run folders), science/ (measures,
claims, the study; sweeps/), recording/ (bags, pictures), cli/ (the command line, bad input and
faults), gym/ and nodes/ (the ROS 2 graph). Every test that starts ROS nodes carries the `ros`
marker, so the rest runs alone: `scripts/test -m "not ros"` (or one folder: `scripts/test
tests/core`). This folder is on sys.path (graph_helpers)."""
import pytest

# The module fixtures that start ROS participants or node processes (tests/graph_helpers.py).
ROS_FIXTURES = {"ros", "procs"}


def pytest_configure(config):
    config.addinivalue_line("markers", "ros: starts ROS 2 nodes (rclpy in the test process or "
                                       "node processes); deselect with -m 'not ros'")
    config.addinivalue_line("markers", "install: pip-installs the core into a fresh venv and "
                                       "runs it there (about 90 s); deselect with "
                                       "-m 'not install'")


def pytest_collection_modifyitems(items):
    """A test that asks for a ROS fixture without the marker would slip into the quick subset."""
    unmarked = [item.nodeid for item in items
                if ROS_FIXTURES & set(getattr(item, "fixturenames", ()))
                and item.get_closest_marker("ros") is None]
    if unmarked:
        raise pytest.UsageError("tests that start ROS nodes need @pytest.mark.ros: "
                                + ", ".join(unmarked))
