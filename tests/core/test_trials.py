"""Whole trials: the engine's two drivers (whole trials compiled, or one act() call per cycle) must
not change a single bit of the results, and the paper's measures follow from a contact history."""
import numpy as np
import pytest

from econet_ros import genome
from econet_ros.config import Config
from econet_ros.plugins import make_controller
from econet_ros.trials import Tally, TrialMeasures, run_trials, start_tally, tally_contact
from econet_ros.world import World, sample_setups

CONFIG = Config()


class PerCycle:
    """Wraps a controller so that the engine must call act() every cycle."""

    def __init__(self, inner):
        self.inner = inner

    def act(self, obs):
        return self.inner.act(obs)

    def compiled(self, cycles):
        return None


@pytest.mark.parametrize("condition", ["normal", "three-layer", "random"])
def test_compiled_and_per_cycle_drivers_agree_exactly(condition):
    n_econets, trials, cycles = 6, 4, 60
    n = n_econets * trials
    rng = np.random.default_rng(4)
    setup = sample_setups(rng, n, CONFIG.model)
    runs = []
    for wrap in (lambda c: c, PerCycle):
        controller = make_controller(condition, n, CONFIG)
        codes = genome.random_genomes(np.random.default_rng(9), n_econets, controller.n_params,
                                      8)
        controller.load(genome.decode(codes, 8, 10.0), noise_seed=17)
        runs.append(run_trials(World(n, CONFIG.model), wrap(controller), setup, cycles,
                               record=True))
    (fast, fast_trace), (slow, slow_trace) = runs
    for field in vars(fast):
        np.testing.assert_array_equal(getattr(fast, field), getattr(slow, field))
    for field in fast_trace._fields:
        np.testing.assert_array_equal(getattr(fast_trace, field), getattr(slow_trace, field),
                                      err_msg=field)
    assert fast_trace.touch[1:].sum() == fast.fitness.sum()


def test_trial_measures_from_a_contact_history():
    contact = np.array([[0, 0, 0], [1, 0, 0], [1, 0, 1], [0, 0, 1], [1, 0, 1]], dtype=bool)
    m = TrialMeasures.from_contact(contact)
    np.testing.assert_array_equal(m.fitness, [3, 0, 3])
    np.testing.assert_array_equal(m.success, [True, False, True])
    np.testing.assert_array_equal(m.latency, [2, 5, 3])
    np.testing.assert_array_equal(m.separations, [1, 0, 0])


def test_compiled_tally_counts_as_the_contact_history_defines():
    """The compiled loops' tally (CPU and GPU) against TrialMeasures.from_contact, the vectorised
    definition, on histories whose start row (cycle 0, before any movement) may be in contact."""
    rng = np.random.default_rng(3)
    cycles, n = 12, 400
    touch = rng.random((cycles + 1, n)) < rng.uniform(0, 1, n)      # rows 0..cycles
    tally = Tally.empty(n)
    for i in range(n):
        start_tally(i, cycles, *tally)
        for t in range(1, cycles + 1):
            tally_contact(t, i, touch[t, i], touch[t - 1, i], *tally)
    expected = TrialMeasures.from_contact(touch[1:])
    found = TrialMeasures.from_tally(tally)
    assert touch[0].any() and not expected.success.all() and expected.separations.any()
    for field in vars(expected):
        np.testing.assert_array_equal(getattr(found, field), getattr(expected, field), field)


def test_the_compiled_loop_unpacks_the_tuples_in_their_field_order():
    """trials.run_block_trials takes its tuples apart by position (numba loses writes through
    field names inside a parallel loop): a reordered field would be read as another."""
    from econet_ros.trials import BehaviourRecord, Policy, Trace
    from econet_ros.world import WorldArrays
    assert WorldArrays._fields == ("body", "body_start", "shoulder", "elbow", "object_xy",
                                   "edge_x", "edge_y")
    assert Policy._fields[::2] == ("weights", "layers", "motor_table")
    assert Policy._fields[5] == "use_table"
    assert Trace._fields == ("body", "shoulder", "elbow", "hand", "hand_object_distance",
                             "touch", "fixated", "motor", "object_xy")
    assert BehaviourRecord._fields == ("pre_contact", "fixated", "values", "hand", "counts",
                                       "angle_high", "angle_low")
    assert Tally._fields == ("fitness", "latency", "separations")
