"""The environment scripts/setup builds: econet_msgs interfaces and the ament_python layout."""
import os
from importlib.metadata import distribution
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]


def test_set_weights_importable_and_generated_here():
    from econet_msgs.srv import SetWeights

    module_file = Path(__import__('econet_msgs').__file__).resolve()
    assert (REPO / 'install' / 'econet_msgs') in module_file.parents
    assert SetWeights.Request.get_fields_and_field_types() == {
        'n_envs': 'uint32',
        'weights_per_network': 'uint32',
        'weights': 'sequence<double>',
        'noise_seed': 'uint64',
        'network': 'string',
    }
    assert SetWeights.Response.get_fields_and_field_types() == {
        'success': 'boolean',
        'message': 'string',
    }


def test_set_weights_request_round_trips_float64_exactly():
    from rclpy.serialization import deserialize_message, serialize_message

    from econet_msgs.srv import SetWeights

    rng = np.random.default_rng(1)
    weights = rng.standard_normal(1000) * 10.0 ** rng.integers(-300, 300, 1000)
    weights[:3] = [np.pi, -0.0, np.finfo(np.float64).tiny]
    req = SetWeights.Request(n_envs=10, weights_per_network=100, weights=weights,
                             noise_seed=2**64 - 1)
    assert req.n_envs * req.weights_per_network == len(req.weights)

    back = deserialize_message(serialize_message(req), SetWeights.Request)
    got = np.asarray(back.weights, dtype=np.float64)
    assert got.shape == (1000,)
    assert np.array_equal(got.view(np.uint64), weights.view(np.uint64))  # bit-exact
    assert (back.n_envs, back.weights_per_network, back.noise_seed) == (10, 100, 2**64 - 1)

    resp = deserialize_message(
        serialize_message(SetWeights.Response(success=True, message='ok')),
        SetWeights.Response)
    assert resp.success and resp.message == 'ok'


def test_ament_python_console_script_layout():
    install = REPO / 'install' / 'econet_ros'
    script = install / 'lib' / 'econet_ros' / 'econet'
    assert script.is_file()
    assert os.access(script, os.X_OK)
    assert script.read_text().startswith('#!')
    eps = [ep for ep in distribution('econet_ros').entry_points
           if ep.group == 'console_scripts' and ep.name == 'econet']
    assert [ep.value for ep in eps] == ['econet_ros.cli:main']
    assert (install / 'share' / 'econet_ros' / 'package.xml').is_file()
    assert (install / 'share' / 'ament_index' / 'resource_index' / 'packages'
            / 'econet_ros').is_file()
