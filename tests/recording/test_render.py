"""Pictures of a trial from an in-process trace (bags render through the same functions)."""
import numpy as np
from PIL import Image

from econet_ros.config import Config
from econet_ros.plugins import make_controller
from econet_ros.trials import run_trials
from econet_ros.recording.render import TrialFrames, animate, filmstrip
from econet_ros.world import World, sample_setups


def test_a_trace_renders_as_animation_and_filmstrip(tmp_path):
    config = Config()
    cycles = 12
    controller = make_controller("reacher", 2, config)
    _, trace = run_trials(World(2, config.model), controller,
                          sample_setups(np.random.default_rng(1), 2, config.model), cycles,
                          record=True)
    frames = TrialFrames.from_trace(trace, 1)
    assert len(frames) == cycles + 1
    np.testing.assert_array_equal(frames.shoulder, trace.shoulder[:, 1])

    gif = animate(frames, config.model, tmp_path / "trial.gif")
    with Image.open(gif) as image:
        assert image.n_frames == cycles + 1
    png = filmstrip(frames, config.model, tmp_path / "trial.png", panels=5)
    with Image.open(png) as image:
        width, height = image.size
        assert width > 3 * height        # five panels in one row
