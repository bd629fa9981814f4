"""The paper's open choices as settings (issue 12): each reading checked on a case worked by
hand, and the defaults leaving stored results as they were."""
import json

import numpy as np
import pytest

from econet_ros import genome
from econet_ros.config import Config, ModelConfig
from econet_ros.world import World


# -- the genome code ----------------------------------------------------------------------------
def test_gray_code_round_trips_and_neighbours_differ_in_one_bit():
    points = np.arange(256, dtype=np.uint8)
    codes = genome.to_gray(points)
    assert sorted(codes) == list(range(256))                 # a permutation of the codes
    np.testing.assert_array_equal(genome.from_gray(codes), points)
    for k in range(255):
        assert genome.flipped_bits(codes[k:k + 1], codes[k + 1:k + 2]) == 1
    # hand-worked: grid point 5 = 0b101 has Gray code 0b111; 6 = 0b110 -> 0b101
    assert (codes[5], codes[6]) == (0b111, 0b101)
    weights = np.array([-10.0, -0.04, 3.3, 10.0])
    for code in ("binary", "gray"):
        coded = genome.encode(weights, 8, 10.0, code)
        np.testing.assert_allclose(genome.decode(coded, 8, 10.0, code), weights, atol=10 / 255)
    assert genome.decode(np.array([0b111], np.uint8), 8, 10.0, "gray")[0] == \
        genome.decode(np.array([5], np.uint8), 8, 10.0, "binary")[0]


# -- the body text's mutation: 2% of the weights, each by a small step --------------------------
@pytest.mark.parametrize("code", ["binary", "gray", "sign-magnitude"])
def test_weight_mutation_moves_two_percent_of_weights_by_small_steps(code):
    rng = np.random.default_rng(4)
    points = rng.integers(10, 246, size=(2000, 160)).astype(np.uint8)   # away from the ends
    codes = genome.codes_of(points, 8, code)
    mutated = genome.mutate(rng, codes, 8, 0.02, mode="weights", step=4, code=code)
    moves = genome.grid_points(mutated, 8, code).astype(int) - points.astype(int)
    changed = moves != 0
    # 320,000 weights at 2%: 6,400 expected, s.d. 79
    assert abs(changed.mean() - 0.02) < 0.001, changed.mean()
    sizes = np.abs(moves[changed])
    assert sizes.min() == 1 and sizes.max() == 4
    assert abs(sizes.mean() - 2.5) < 0.05                     # uniform over 1..4
    assert abs(np.sign(moves[changed]).mean()) < 0.05          # up as often as down


def test_weight_mutation_stops_at_the_ends_of_the_grid():
    rng = np.random.default_rng(1)
    ends = np.tile(np.array([0, 255], np.uint8), (5000, 1))
    mutated = genome.mutate(rng, ends, 8, 1.0, mode="weights", step=3)
    assert mutated.min() == 0 and mutated.max() == 255
    assert set(np.unique(mutated[:, 0])) <= {0, 1, 2, 3}
    assert set(np.unique(mutated[:, 1])) <= {252, 253, 254, 255}


def test_per_bit_flips_change_many_weights_where_the_body_text_changes_few():
    """Why the reading matters: per-bit 2% flips touch about 1 - 0.98^8 = 15% of the weights,
    a fifth of them by a most-significant bit (a jump of about 10 weight units)."""
    rng = np.random.default_rng(0)
    codes = genome.random_genomes(rng, 2000, 160, 8)
    per_bit = genome.mutate(rng, codes, 8, 0.02)
    assert abs((per_bit != codes).mean() - (1 - 0.98 ** 8)) < 0.005
    weights = genome.mutate(rng, codes, 8, 0.02, mode="weights", step=4)
    assert abs((weights != codes).mean() - 0.02) < 0.002


# -- the body axis --------------------------------------------------------------------------------
@pytest.mark.parametrize("axis, expected", [("unbounded", 30 + 450.0), ("within-360", 30 + 360.0)])
def test_a_bounded_body_axis_stops_at_its_limit(axis, expected):
    world = World(1, ModelConfig(body_axis=axis))
    world.body[:] = world.body_start[:] = 30.0
    turn_left = np.array([[1.0, 0.0, 0.0, 0.0, 0.0]])       # 15 degrees a cycle
    for _ in range(30):
        world.step(turn_left)
    assert world.body[0] == expected
    for _ in range(60):                                       # and it turns back freely
        world.step(1.0 - turn_left)
    assert world.body[0] == (30 - 360.0 if axis == "within-360" else expected - 900.0)


# -- the shoulder convention ------------------------------------------------------------------------
def posture(convention, shoulder, elbow):
    world = World(1, ModelConfig(shoulder_convention=convention))
    world.body[:], world.shoulder[:], world.elbow[:] = 0.0, shoulder, elbow
    world.object_xy[:] = (-40.0, 0.0)                       # behind the eye
    world.refresh()
    return world


def test_forward_shoulder_points_the_extended_arm_along_the_gaze():
    straight = posture("forward", 180.0, 180.0).arm_points()[0]
    np.testing.assert_allclose(straight[3], (50.0, 0.0), atol=1e-12)      # the tip
    np.testing.assert_allclose(straight[1], (25.0, 0.0), atol=1e-12)      # the elbow
    flexed = posture("forward", 90.0, 180.0).arm_points()[0]               # 90 deg to the left
    np.testing.assert_allclose(flexed[3], (0.0, 50.0), atol=1e-12)
    centred = posture("centred", 180.0, 180.0).arm_points()[0]             # 90 deg to the right
    np.testing.assert_allclose(centred[3], (0.0, -50.0), atol=1e-12)


@pytest.mark.parametrize("shoulder, elbow", [(179.5, 180.0), (150.0, 85.0), (100.0, 3.0),
                                             (95.0, 0.0)])
def test_forward_posture_sees_what_the_centred_one_90_degrees_lower_sees(shoulder, elbow):
    forward = posture("forward", shoulder, elbow)
    centred = posture("centred", shoulder - 90.0, elbow)
    np.testing.assert_allclose(forward.observe().vision, centred.observe().vision, atol=1e-12)
    np.testing.assert_allclose(forward.arm_points(), centred.arm_points(), atol=1e-12)
    assert forward.observe().proprio[0, 0] == shoulder / 180.0       # the joint's own angle


# -- stored results ------------------------------------------------------------------------------------
def test_added_settings_are_stored_only_when_not_default():
    stored = Config().to_dict()
    for section, name in (("model", "body_axis"), ("model", "shoulder_convention"),
                          ("model", "angle_steps"), ("model", "joint_limit"),
                          ("evolution", "genome_code"), ("evolution", "mutation_step")):
        assert name not in stored[section]
    changed = Config().replace(**{"evolution.genome_code": "gray",
                                  "model.body_axis": "within-360"})
    data = json.loads(changed.to_json())
    assert data["evolution"]["genome_code"] == "gray" and data["model"]["body_axis"] == "within-360"
    assert Config.from_dict(data) == changed and Config.from_dict(stored) == Config()
