"""Bags without a graph: the `econet bag` commands on bags recorded in process, replay that catches
a tampered bag, pictures and real time in a recorded bag, repair of complete chunks, and one-
line errors for bad paths (bags recorded through the running graph:
tests/nodes/test_recording_nodes.py)."""
import time

import numpy as np
import pytest

from econet_ros.cli import main
from econet_ros.config import Config
from econet_ros.plugins import make_controller
from econet_ros.recording import bags
from econet_ros.world import World, sample_setups

from graph_helpers import REPO


def recorded_in_process(path, n=3, cycles=30, tamper=False):
    """Trials of the reacher written in process; with tamper, one command is changed."""
    config = Config()
    world, controller = World(n, config.model), make_controller("reacher", n, config)
    writer = bags.TrialBagWriter(path)
    setup = sample_setups(np.random.default_rng(3), n, config.model)
    obs = world.reset(setup)
    writer.start(setup, config.model, cycles)
    writer.sensors(obs, cycles)
    for t in range(cycles):
        motor = controller.act(obs)
        recorded = motor.copy()
        if tamper and t == 12:
            recorded[1, 1] = min(recorded[1, 1] + 0.3, 1.0) if recorded[1, 1] < 0.5 else 0.0
        writer.command(t, recorded)
        obs = world.step(motor)
        writer.sensors(obs, cycles)
    writer.close()
    return path


def test_replay_reproduces_a_bag_and_catches_a_tampered_one(tmp_path, capsys):
    good = recorded_in_process(tmp_path / "good")
    assert main(["bag", "replay", str(good)]) == 0
    assert "replay: identical" in capsys.readouterr().out
    bad = recorded_in_process(tmp_path / "bad", tamper=True)
    assert main(["bag", "replay", str(bad)]) == 1
    text = capsys.readouterr().out
    assert "MISMATCH at trial 1 cycle 13 environment 1" in text and "DIFFERENT" in text


def test_evaluate_record_gives_the_same_measures_from_the_bag(tmp_path, capsys):
    bag = tmp_path / "evaluated"
    assert main(["evaluate", "--controller", "reacher", "--trials", "5", "--cycles", "60",
                 "--record", str(bag)]) == 0
    printed = capsys.readouterr().out
    measures = bags.read_bag(bag).trials[0].measures()
    assert f"fitness      mean {measures.fitness.mean():.1f}" in printed
    assert f"success      {int(measures.success.sum())}/5" in printed


@pytest.mark.parametrize("make, fragment", [
    (lambda d: d / "missing", "no such bag"),
    (lambda d: d, "is not a rosbag2 bag: the folder has no metadata.yaml"),
    (lambda d: (d / "notes.txt").write_text("hello") and d / "notes.txt",
     "is not a bag: expected a bag folder or an .mcap file"),
    ("truncated-file", "cannot read bag"),
    ("truncated-folder", "cannot read bag"),
])
@pytest.mark.parametrize("verb", ["measures", "replay", "render", "info"])
def test_bad_bag_paths_are_one_line_errors(tmp_path, capsys, make, fragment, verb):
    if isinstance(make, str):
        whole = recorded_in_process(tmp_path / "whole")
        data = (whole / "whole.mcap").read_bytes()
        if make == "truncated-file":
            target = tmp_path / "cut.mcap"
        else:
            target = tmp_path / "cutbag"
            target.mkdir()
            (target / "metadata.yaml").write_bytes((whole / "metadata.yaml").read_bytes())
            target = target / "whole.mcap"
        target.write_bytes(data[: len(data) // 2])
        path = target if make == "truncated-file" else target.parent
    else:
        path = make(tmp_path)
    status = main(["bag", verb, str(path)])
    err = capsys.readouterr().err
    assert status == 2
    assert err.count("\n") == 1 and err.startswith("econet: error:"), err
    assert fragment in err


def test_evaluate_record_carries_pictures_frame_and_real_time(tmp_path):
    """`econet evaluate --record` bags hold joint_states and markers every cycle, the /tf_static
    of their frame, wall-clock stamps that increase; the Foxglove layout in docs/ shows them."""
    import json

    from rosbags.rosbag2 import Reader

    from econet_ros.recording.messages import typestore

    bag, before = tmp_path / "pictured", time.time_ns()
    assert main(["evaluate", "--controller", "reacher", "--trials", "2", "--cycles", "20",
                 "--record", str(bag)]) == 0
    after = time.time_ns()
    store = typestore()
    with Reader(bag) as reader:
        messages = [(c.topic, t, store.deserialize_cdr(raw, c.msgtype))
                    for c, t, raw in reader.messages()]
    stamps = [t for _, t, _ in messages]
    assert stamps == sorted(set(stamps)) and before <= stamps[0] and stamps[-1] <= after
    by_topic = {}
    for topic, _, msg in messages:
        by_topic.setdefault(topic, []).append(msg)
    assert len(by_topic["/joint_states"]) == len(by_topic["/markers"]) == 21
    (static,) = by_topic["/tf_static"]
    (transform,) = static.transforms
    assert (transform.header.frame_id, transform.child_frame_id) == ("map", "econet")
    markers = by_topic["/markers"][0].markers
    assert [m.ns for m in markers] == ["arm", "hand", "eye_field", "object"]
    assert {m.header.frame_id for m in markers} == {"econet"}
    assert list(by_topic["/joint_states"][0].name) == ["body", "shoulder", "elbow"]

    layout = json.loads((REPO / "docs" / "foxglove-layout.json").read_text())
    scene = layout["configById"]["3D!econet"]
    assert scene["followTf"] == "econet" and scene["topics"]["/markers"]["visible"]
    paths = [p["value"].split(".")[0] for p in layout["configById"]["Plot!joints"]["paths"]]
    assert set(paths) | {layout["configById"]["RawMessages!touch"]["topicPath"]} <= \
        set(by_topic)


def test_repair_recovers_complete_chunks_and_refuses_an_empty_file(tmp_path, capsys):
    """A bag cut off after its last complete chunk and without metadata.yaml (what a kill
    leaves) is repaired into a bag with the same trial; an empty .mcap is one line."""
    whole = recorded_in_process(tmp_path / "whole")
    data = (whole / "whole.mcap").read_bytes()
    cut = tmp_path / "cut"
    cut.mkdir()
    (cut / "cut.mcap").write_bytes(data[:len(data) - 200])     # footer and summary gone
    assert main(["bag", "repair", str(cut / "cut.mcap"), "--out", str(tmp_path / "fixed")]) == 0
    assert "repaired:" in capsys.readouterr().out
    (want,), (got,) = bags.read_bag(whole).trials, bags.read_bag(tmp_path / "fixed").trials
    assert got.complete and np.array_equal(got.touch, want.touch)
    assert np.array_equal(got.motor, want.motor)
    empty = tmp_path / "empty"
    empty.mkdir()
    (empty / "empty.mcap").write_bytes(b"")
    assert main(["bag", "repair", str(empty)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "nothing to recover" in err
