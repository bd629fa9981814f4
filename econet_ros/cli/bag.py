"""``econet bag info|measures|render|replay BAG``: recorded trials, from the bag alone.

    info      topics, types and message counts, trials, custom data (like ``ros2 bag info``)
    repair    recover a bag whose recorder was killed (no metadata.yaml, no MCAP footer) from
              its complete chunks, as a new bag
    measures  the paper's trial measures (fitness, success, latency, separations) per
              environment, computed from the recorded touch messages
    render    a GIF animation and a PNG filmstrip of one environment's trial
    replay    re-apply the recorded commands to a fresh world and check that it reproduces every
              recorded sensor message exactly (exit status 1 if not)

A BAG is a bag folder (with metadata.yaml) or its .mcap file. Bad input ends in one line.
"""
from __future__ import annotations

import argparse
from pathlib import Path

from ..errors import UsageError
from ..recording.bags import read_bag, replay
from ..files import ensure_writable
from .options import Parser


def add_parser(commands) -> None:
    bag = commands.add_parser("bag", help="inspect, score, render and replay recorded trials",
                              description=__doc__.split("\n\n")[0])
    verbs = bag.add_subparsers(dest="verb", required=True, parser_class=Parser)
    for name, handler, text in (
            ("info", _info, "topics, message counts, trials and custom data"),
            ("measures", _measures, "trial measures computed from the recorded messages"),
            ("render", _render, "GIF animation and PNG filmstrip of one trial"),
            ("replay", _replay, "check that the commands reproduce the recorded sensors"),
            ("repair", _repair, "recover a killed recording's complete chunks as a new bag")):
        verb = verbs.add_parser(name, help=text, description=text)
        verb.add_argument("bag", metavar="BAG", help="bag folder (or its .mcap file)")
        if name == "repair":
            verb.add_argument("--out", default=None, metavar="NEW",
                              help="the repaired bag, a new folder (default: BAG-repaired)")
        if name in ("measures", "render"):
            verb.add_argument("--trial", type=int, default=None,
                              help="trial number as recorded (default: every trial / the "
                                   "first)")
        if name == "render":
            verb.add_argument("--env", type=int, default=0,
                              help="environment of the batch to draw (default: 0)")
            verb.add_argument("--out", default=None, metavar="DIR",
                              help="folder for the pictures (default: next to the bag)")
            verb.add_argument("--fps", type=int, default=10, help="GIF frames per second")
        verb.set_defaults(handler=handler)


def _trials(bag, number: int | None):
    if not bag.trials:
        raise UsageError(f"{bag.path} holds no econet trials (no trial_start messages)")
    if number is None:
        return bag.trials
    chosen = [t for t in bag.trials if t.trial == number]
    if not chosen:
        raise UsageError(f"{bag.path} has no trial {number} (it has "
                         f"{', '.join(str(t.trial) for t in bag.trials)})")
    return chosen


def _info(args: argparse.Namespace) -> int:
    bag = read_bag(Path(args.bag))
    print(f"bag: {bag.path}  ({sum(n for _, n in bag.topics.values())} messages, "
          f"{bag.duration_s:.2f} s)")
    width = max((len(t) for t in bag.topics), default=5)
    for topic, (msgtype, count) in bag.topics.items():
        print(f"  {topic:<{width}}  {count:>7}  {msgtype}")
    for trial, count in sorted(bag.unstarted.items()):
        print(f"trial {trial}: {count} message(s) without its trial_start (not replayable)")
    for trial in bag.trials:
        state = "complete" if trial.complete else \
            f"incomplete: cycles 0-{max(trial.heard_cycles, 0)} of {trial.cycles}"
        print(f"trial {trial.trial}: {trial.n_envs} environment(s) x {trial.cycles} cycles "
              f"({state})")
    for key, value in sorted(bag.custom.items()):
        print(f"{key}: {value}")
    return 0


def _measures(args: argparse.Namespace) -> int:
    bag = read_bag(Path(args.bag))
    for trial in _trials(bag, args.trial):
        m = trial.measures()
        heard = trial.heard_cycles
        note = "" if heard == trial.cycles else f" (incomplete: only cycles 1-{heard} recorded)"
        print(f"trial {trial.trial}: {trial.n_envs} environment(s) x {trial.cycles} cycles"
              f"{note}")
        print("  env  fitness  success  latency  separations")
        for i in range(trial.n_envs):
            print(f"  {i:>3}  {int(m.fitness[i]):>7}  {'yes' if m.success[i] else 'no':>7}  "
                  f"{int(m.latency[i]):>7}  {int(m.separations[i]):>11}")
        print(f"  all  fitness {int(m.fitness.sum())} (mean {m.fitness.mean():.1f}), "
              f"success {int(m.success.sum())}/{trial.n_envs}, mean latency "
              f"{m.latency.mean():.1f}, separations {int(m.separations.sum())}")
    return 0


def _render(args: argparse.Namespace) -> int:
    from ..recording.render import TrialFrames, animate, filmstrip   # matplotlib: late

    bag = read_bag(Path(args.bag))
    trial = _trials(bag, args.trial)[0]
    if not 0 <= args.env < trial.n_envs:
        raise UsageError(f"--env must be between 0 and {trial.n_envs - 1} (trial {trial.trial} "
                         f"has {trial.n_envs} environment(s)), got {args.env}")
    if args.fps < 1:
        raise UsageError(f"--fps must be at least 1, got {args.fps}")
    out = Path(args.out) if args.out else bag.path.parent
    ensure_writable(out)
    states = replay(trial)     # the states behind the recorded sensors (from start + commands)
    k, e = states.checked, args.env
    frames = TrialFrames(states.body[:, e], states.shoulder[:, e], states.elbow[:, e],
                         trial.touch[:k + 1, e], trial.setup.object_xy[e])
    stem = f"{bag.path.stem}-trial{trial.trial}-env{e}"
    gif = animate(frames, trial.model, out / f"{stem}.gif", fps=args.fps)
    png = filmstrip(frames, trial.model, out / f"{stem}.png")
    print(f"animation: {gif}\nfilmstrip: {png}")
    if states.mismatch:
        print(f"warning: the replay diverges from the recording at {states.mismatch}; the "
              "pictures stop there")
    return 0


def _replay(args: argparse.Namespace) -> int:
    bag = read_bag(Path(args.bag))
    ok, checked = True, 0
    for trial in _trials(bag, None):
        if not trial.lockstep:
            print(f"trial {trial.trial}: not checked (a free-running world applies the newest "
                  "command at its own rate, so its commands do not replay exactly)")
            continue
        checked += 1
        result = replay(trial)
        if result.mismatch:
            ok = False
            print(f"trial {trial.trial}: MISMATCH at {result.mismatch}")
        elif result.checked < trial.cycles:
            print(f"trial {trial.trial}: {trial.n_envs} environment(s), cycles 0-"
                  f"{result.checked} reproduced exactly (the recording stops there)")
        else:
            print(f"trial {trial.trial}: {trial.n_envs} environment(s) x {trial.cycles} cycles "
                  "reproduced exactly")
    if not checked:
        print("replay: nothing checked (no lockstep trial in the bag)")
        return 1
    print("replay: identical" if ok else "replay: DIFFERENT")
    return 0 if ok else 1


def _repair(args: argparse.Namespace) -> int:
    from ..recording.repair import repair

    source = Path(args.bag)
    out = Path(args.out) if args.out else source.with_name(source.stem + "-repaired")
    count, found = repair(source, out)
    print(f"repaired: {out} ({count} messages on {len(found.topics)} topics from "
          f"{found.chunks} complete chunk(s); {found.lost_bytes} bytes after them were "
          "incomplete and are lost)")
    return 0
