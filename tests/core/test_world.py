"""Geometry, senses and motor mapping of the world, checked against cases worked by hand and
against a brute-force sampling of the visual field."""
import math
import re

import numpy as np
import pytest

from econet_ros.config import ModelConfig
from econet_ros.world import TrialSetup, World, sample_setups

MODEL = ModelConfig()
FAR_BEHIND = (-40.0, 0.0)   # an object behind the eye when the body axis points along +x


def world_at(body, shoulder, elbow, obj=FAR_BEHIND):
    """A world in the given state, set directly: geometry tests put the object anywhere, also
    outside the trial annulus that World.reset enforces."""
    world = World(1, MODEL)
    world.body[:], world.shoulder[:], world.elbow[:] = body, shoulder, elbow
    world.object_xy[:] = obj
    world.refresh()
    return world


def polar(distance, degrees):
    return (distance * math.cos(math.radians(degrees)), distance * math.sin(math.radians(degrees)))


def test_only_the_hand_in_view_gives_the_hand_worked_vector():
    # Upper arm 0.5 deg left of the gaze, elbow straight: the hand is the stretch 45-50 units
    # out along 0.5 deg, inside one-degree window 32, which belongs to visual unit 4.
    world = world_at(body=0, shoulder=89.5, elbow=180)
    vision = world.observe().vision[0]
    expected = np.zeros(8)
    expected[4] = (1 - 45 / 50) / 8
    np.testing.assert_allclose(vision, expected, atol=1e-12)
    assert not world.observe().fixated[0]


def test_nearer_object_occludes_the_hand_behind_it():
    obj = polar(30, 0.5)            # in front of the hand, on the same line of sight
    both = world_at(0, 89.5, 180, obj).observe()
    arm_away = world_at(0, 0, 180, obj).observe()   # arm pointing 90 deg right, out of view
    np.testing.assert_allclose(both.vision, arm_away.vision, atol=1e-12)
    # window 32 holds the object's near edge: 1 - (30 - 2)/50
    assert both.vision[0, 4] >= (1 - 28 / 50) / 8
    assert both.fixated[0]


def test_nearer_hand_hides_the_object_in_its_window_only():
    obj = polar(48, 0.5)
    world = world_at(0, 89.5, 180, obj)
    vision = world.observe().vision[0]
    alone = world_at(0, 0, 180, obj).observe().vision[0]
    # the hand (45) is nearer than the object's edge (46) in window 32: unit 4 sees more
    assert vision[4] > alone[4]
    assert world.observe().fixated[0]    # the object still shows in neighbouring windows


def test_a_folded_elbow_puts_the_tip_on_the_eye_and_the_hand_across_a_quarter_turn():
    # Folded (q_e = 0), the forearm lies back along the upper arm (at -29.5 deg) and its tip is
    # on the eye. Vision takes the limit of a slightly bent elbow, whose tip nears the eye from
    # 90 deg left of the upper arm: the hand fills -29.5 to +60.5 deg at distance 0, so windows
    # 2-63 of the field (window 2 starts at -30 deg).
    world = world_at(body=0, shoulder=119.5, elbow=0)
    assert tuple(world.arm_points()[0, 3]) == (0.0, 0.0)
    expected = np.ones(8)
    expected[0] = 6 / 8
    np.testing.assert_allclose(world.observe().vision[0], expected, atol=1e-12)
    bent = world_at(body=0, shoulder=119.5, elbow=1e-4).observe().vision[0]
    np.testing.assert_allclose(bent, expected, atol=1e-3)
    # upper arm pointing left (q_s = 0): the quarter turn from 90 to 180 deg is out of view
    assert world_at(body=0, shoulder=0, elbow=0).observe().vision.sum() == 0


def brute_force_vision(world, samples=4000):
    """Sample hand and object outlines densely and keep the nearest point per window."""
    m = world.model
    points = world.arm_points()[0]
    t = np.linspace(0, 1, samples)[:, None]
    hand = points[2] + t * (points[3] - points[2])
    angles = np.linspace(0, 2 * np.pi, samples)
    ring = np.linspace(0, m.object_radius, 25)
    disk = (world.object_xy[0] + (ring[None, :, None] * np.stack(
        [np.cos(angles), np.sin(angles)], 1)[:, None, :])).reshape(-1, 2)
    allpts = np.concatenate([hand, disk])
    rel = np.degrees(np.arctan2(allpts[:, 1], allpts[:, 0])) - world.body[0]
    rel = (rel + 180) % 360 - 180
    dist = np.hypot(allpts[:, 0], allpts[:, 1])
    windows = np.full(64, np.inf)
    inside = np.abs(rel) < 32
    idx = np.floor(rel[inside] + 32).astype(int)
    np.minimum.at(windows, idx, dist[inside])
    values = np.where(np.isfinite(windows), np.maximum(1 - windows / 50, 0), 0)
    return values.reshape(8, 8).mean(axis=1)


def test_vision_matches_brute_force_sampling():
    rng = np.random.default_rng(3)
    checked = 0
    for _ in range(200):
        setup = sample_setups(rng, 1, MODEL)
        setup.body[:] = math.degrees(math.atan2(setup.object_xy[0, 1], setup.object_xy[0, 0])) \
            + rng.uniform(-40, 40)
        world = World(1, MODEL)
        world.reset(setup)
        vision = world.observe().vision[0]
        if vision.sum() == 0:
            continue
        np.testing.assert_allclose(vision, brute_force_vision(world), atol=3e-3)
        checked += 1
    assert checked > 60


def test_proprioception_is_scaled_angle_and_complement():
    obs = world_at(0, 45, 135).observe()
    np.testing.assert_allclose(obs.proprio[0], [0.25, 0.75, 0.75, 0.25])


def test_motor_outputs_map_to_at_most_15_degrees():
    world = world_at(0, 90, 90)
    world.step(np.array([[1.0, 1.0, 0.0, 0.25, 0.75]]))
    assert world.body[0] == pytest.approx(15)
    assert world.shoulder[0] == pytest.approx(75)     # full flexion: 15 deg, to the left
    assert world.elbow[0] == pytest.approx(97.5)      # extension by 0.5 * 15
    world.step(np.array([[0.0, 0.5, 0.5, 0.5, 0.5]]))  # equal activation holds the joints
    assert (world.body[0], world.shoulder[0], world.elbow[0]) == pytest.approx((0, 75, 97.5))


def test_flexion_rotates_the_upper_arm_left():
    world = world_at(0, 90, 180)
    before = math.atan2(*world.arm_points()[0, 1][::-1])
    world.step(np.array([[0.5, 1, 0, 0.5, 0.5]]))
    assert math.atan2(*world.arm_points()[0, 1][::-1]) - before == pytest.approx(
        math.radians(15))


def test_joints_stop_at_their_limits():
    world = world_at(0, 10, 170)
    for _ in range(5):
        world.step(np.array([[0.5, 1, 0, 0, 1]]))   # flex shoulder, extend elbow
    assert world.shoulder[0] == 0.0 and world.elbow[0] == 180.0
    for _ in range(20):
        world.step(np.array([[0.5, 0, 1, 1, 0]]))
    assert world.shoulder[0] == 180.0 and world.elbow[0] == 0.0


def test_body_axis_drags_the_arm_round_a_full_circle():
    world = world_at(0, 120, 60)
    start = world.arm_points()[0].copy()
    for step in range(1, 25):                        # 24 x 15 deg = 360 deg
        world.step(np.array([[1.0, 0.5, 0.5, 0.5, 0.5]]))
        if step == 6:                                # a quarter turn: the arm rotated 90 deg
            rotated = start @ np.array([[0, 1], [-1, 0]])
            np.testing.assert_allclose(world.arm_points()[0], rotated, atol=1e-9)
    assert world.body[0] == pytest.approx(360)
    assert (world.shoulder[0], world.elbow[0]) == (120, 60)
    np.testing.assert_allclose(world.arm_points()[0], start, atol=1e-9)


def test_only_the_last_five_units_of_the_forearm_touch():
    # straight arm along +x: the forearm covers x = 25..50, the hand x = 45..50
    for x, expected in ((35.0, 0.0), (42.5, 0.0), (47.0, 1.0), (51.5, 1.0), (52.5, 0.0)):
        obj = (x, 1.0)                      # radius 2: within reach of the segment's line
        touch = world_at(0, 90, 180, obj).observe().touch[0]
        assert touch == expected, (x, touch)


def test_a_batch_equals_its_environments_run_alone():
    rng = np.random.default_rng(5)
    setup = sample_setups(rng, 6, MODEL)
    motor = rng.random((10, 6, 5))
    batch = World(6, MODEL)
    batch.reset(setup)
    singles = [World(1, MODEL) for _ in range(6)]
    for i, world in enumerate(singles):
        world.reset(setup.take(np.array([i])))
    for t in range(10):
        obs = batch.step(motor[t])
        for i, world in enumerate(singles):
            single = world.step(motor[t, i:i + 1])
            np.testing.assert_array_equal(single.vision[0], obs.vision[i])
            assert single.touch[0] == obs.touch[i]


def test_bad_motor_commands_are_refused():
    world = world_at(0, 90, 90)
    with pytest.raises(ValueError, match="shape"):
        world.step(np.zeros((1, 4)))
    with pytest.raises(ValueError, match="NaN"):
        world.step(np.array([[np.nan, 0, 0, 0, 0]]))


def test_objects_are_placed_within_reach():
    setup = sample_setups(np.random.default_rng(0), 5000, MODEL)
    distance = np.hypot(*setup.object_xy.T)
    assert distance.min() >= MODEL.reach_min and distance.max() <= MODEL.reach_max
    assert setup.shoulder.min() >= 0 and setup.shoulder.max() <= 180


def test_an_observation_is_not_changed_by_later_cycles():
    world = world_at(0, 89.5, 180, polar(30, 0.5))
    first = world.observe()
    kept = [a.copy() for a in (first.vision, first.proprio, first.touch, first.fixated)]
    for _ in range(3):
        world.step(np.array([[1.0, 1.0, 0.0, 1.0, 0.0]]))
    world.refresh()
    for before, now in zip(kept, (first.vision, first.proprio, first.touch, first.fixated)):
        np.testing.assert_array_equal(before, now)


def test_a_refused_motor_command_changes_nothing():
    world = World(3, MODEL)
    world.reset(sample_setups(np.random.default_rng(2), 3, MODEL))
    state = (world.body.copy(), world.shoulder.copy(), world.elbow.copy(), world.cycle)
    motor = np.full((3, 5), 0.9)
    motor[2, 4] = np.inf
    with pytest.raises(ValueError, match="infinite"):
        world.step(motor)
    np.testing.assert_array_equal(world.body, state[0])
    np.testing.assert_array_equal(world.shoulder, state[1])
    np.testing.assert_array_equal(world.elbow, state[2])
    assert world.cycle == state[3]


def test_motor_outputs_outside_0_1_are_clipped():
    clipped, raw = world_at(0, 90, 90), world_at(0, 90, 90)
    clipped.step(np.array([[1.0, 1.0, 0.0, 0.0, 1.0]]))
    raw.step(np.array([[7.0, 3.0, -2.0, -1.0, 1.5]]))
    assert (raw.body[0], raw.shoulder[0], raw.elbow[0]) == \
        (clipped.body[0], clipped.shoulder[0], clipped.elbow[0])


def test_kernel_cache_folder_follows_every_module_with_kernels(tmp_path):
    """A change to any module whose functions a cached kernel may inline gives a new numba
    cache folder (numba itself only checks the defining file's timestamp)."""
    import shutil
    from pathlib import Path

    import econet_ros
    package = Path(econet_ros.__file__).parent
    for name in econet_ros.KERNEL_MODULES:
        (tmp_path / name).parent.mkdir(exist_ok=True)
        shutil.copy(package / name, tmp_path / name)
    before = econet_ros._kernel_cache_dir(tmp_path)
    assert before == econet_ros._kernel_cache_dir(tmp_path)
    seen = {before}
    for name in econet_ros.KERNEL_MODULES:
        with open(tmp_path / name, "a") as source:
            source.write("\n# edited\n")
        seen.add(econet_ros._kernel_cache_dir(tmp_path))
    assert len(seen) == 1 + len(econet_ros.KERNEL_MODULES)


@pytest.mark.parametrize("change, fragment", [
    ({"shoulder": np.array([181.0])}, "shoulder angles must be between 0 and 180 degrees"),
    ({"elbow": np.array([-0.5])}, "elbow angles must be between 0 and 180 degrees, got -0.5"),
    ({"body": np.array([1e300])}, "body angles must be between -360 and 360 degrees, got 1e+300"),
    ({"body": np.array([-360.5])}, "body angles must be between -360 and 360 degrees, got -360.5"),
    ({"object_xy": np.array([[60.0, 0.0]])}, "object at distance 60.00 is out of reach"),
    ({"body": np.array([np.nan])}, "body contains NaN or infinite values"),
    ({"object_xy": np.zeros((2, 2))}, "object_xy has shape (2, 2), expected (1, 2)"),
])
def test_reset_refuses_what_it_cannot_run_instead_of_clipping(change, fragment):
    from econet_ros.errors import SetupError
    setup = TrialSetup(np.array([[30.0, 0.0]]), np.array([0.0]), np.array([90.0]),
                       np.array([90.0]))
    World(1, MODEL).reset(setup)                     # the unchanged setup is fine
    for name, value in change.items():
        setattr(setup, name, value)
    with pytest.raises(SetupError, match=re.escape(fragment)):
        World(1, MODEL).reset(setup)


def test_the_papers_figure_1_vision_example():
    """The Appendix: in Figure 1 (shoulder about 126 degrees, elbow about 85, the object out of
    view) the visual units read (0 0 0 0 0.19 0.17 0 [0]). Worked by hand with the documented
    geometry: the upper arm points 36 degrees right of the gaze, the elbow bends it 95 degrees
    back to the left, so the hand runs from 30.6 units at 4.5 degrees to 33.8 units at 11.5
    degrees left of the gaze: windows 36-43, half of unit 4 and half of unit 5, at about
    1 - 32/50."""
    vision = world_at(body=0, shoulder=126, elbow=85).observe().vision[0]
    np.testing.assert_allclose(vision, [0, 0, 0, 0, 0.19, 0.17, 0, 0], atol=0.005)
