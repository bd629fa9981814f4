"""Which of a world's cycles get a picture (recording/display.py's PictureClock): every k-th
cycle where the display rate divides the world's fixed rate, however unevenly the cycles come;
by the wall clock where it does not, or where the world has no fixed rate (lockstep)."""
import numpy as np
import pytest

from econet_ros.recording.display import PictureClock, cycles_per_picture


def jittered_times(n: int, rate_hz: float, jitter_s: float, seed: int = 0) -> np.ndarray:
    """Monotonic times of n timer callbacks at rate_hz, each early or late by up to jitter_s."""
    rng = np.random.default_rng(seed)
    return np.arange(n) / rate_hz + rng.uniform(-jitter_s, jitter_s, n)


def pictured(clock: PictureClock, times, last_final: bool = False) -> list[int]:
    n = len(times)
    return [cycle for cycle, now in enumerate(times)
            if clock.due(cycle, last_final and cycle == n - 1, float(now))]


@pytest.mark.parametrize("display, world, k", [
    (20.0, 20.0, 1), (10.0, 20.0, 2), (20.0, 60.0, 3), (0.5, 10.0, 20), (25.0, 20.0, 1),
    (0.0, 20.0, 1), (0.0, None, 1), (20.0, 50.0, None), (7.0, 20.0, None), (20.0, None, None)])
def test_cycles_per_picture_where_the_display_rate_divides_the_worlds(display, world, k):
    assert cycles_per_picture(display, world) == k


def test_matching_rates_picture_every_cycle_however_jittery_the_timer():
    times = jittered_times(200, 20.0, jitter_s=0.02)
    assert pictured(PictureClock(20.0, 20.0), times) == list(range(200))
    # the wall clock, for comparison, drops the cycles whose callback came early
    assert len(pictured(PictureClock(20.0, None), times)) < 180


def test_a_dividing_display_rate_pictures_every_kth_cycle_and_the_last():
    times = jittered_times(101, 20.0, jitter_s=0.02)
    assert pictured(PictureClock(5.0, 20.0), times, last_final=True) == [*range(0, 101, 4)]
    assert pictured(PictureClock(10.0, 20.0), times[:100], last_final=True) == [
        *range(0, 100, 2), 99]


def test_without_a_dividing_rate_the_wall_clock_throttles():
    times = np.arange(64) / 16             # lockstep at 16 cycles/s, 4 pictures a second
    lockstep = PictureClock(4.0, None)
    assert pictured(lockstep, times) == list(range(0, 64, 4))
    assert lockstep.due(64, True, 3.8)             # a trial's last cycle always
    assert not lockstep.due(0, False, 3.9)         # too soon after it ...
    lockstep.restart()
    assert lockstep.due(0, False, 3.9)             # ... unless a new trial starts
    assert len(pictured(PictureClock(7.0, 20.0), np.arange(200) / 20)) == 67
