"""Starting graph nodes as separate OS processes for the tests, and talking to them."""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


class Processes:
    """Node processes of one test module; every one is killed at the end, even on failure."""

    def __init__(self, log_dir: Path):
        self.log_dir = Path(log_dir)
        self.procs: list[tuple[subprocess.Popen, Path]] = []

    def start(self, node: str, namespace: str, *params: str, name: str | None = None,
              module: str | None = None, env: dict | None = None):
        """Start econet_ros' `node` (world, controller, ...), or any other `module` run with
        python -m, in `namespace` with `params` (name:=value); returns (process, log path)."""
        args = [sys.executable, "-m", module or f"econet_ros.nodes.{node}_node", "--ros-args",
                "-r", f"__ns:={namespace}"]
        for param in params:
            args += ["-p", param]
        log = self.log_dir / f"{name or node}-{namespace.strip('/')}-{len(self.procs)}.log"
        handle = open(log, "w")
        proc = subprocess.Popen(args, cwd=REPO, stdout=handle, stderr=subprocess.STDOUT,
                                stdin=subprocess.DEVNULL, start_new_session=True, env=env)
        handle.close()
        self.procs.append((proc, log))
        return proc, log

    def kill(self, proc: subprocess.Popen, sig=signal.SIGINT) -> None:
        if proc.poll() is None:
            os.killpg(proc.pid, sig)
            try:
                proc.wait(5)
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)
                proc.wait()

    def stop_all(self) -> None:
        for proc, _ in self.procs:
            if proc.poll() is None:
                os.killpg(proc.pid, signal.SIGINT)
        for proc, _ in self.procs:
            self.kill(proc, signal.SIGKILL) if _waited(proc) else None


def _waited(proc) -> bool:
    try:
        proc.wait(5)
        return False
    except subprocess.TimeoutExpired:
        return True


def spin_until(executor, done, timeout: float = 30.0, what: str = "condition") -> None:
    """Spin until done() is true; fail the test (not hang) after a generous timeout."""
    deadline = time.monotonic() + timeout
    while not done():
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out waiting for {what}")
        executor.spin_once(timeout_sec=0.05)


def call(executor, client, request, timeout: float = 30.0, resend_sec: float = 5.0):
    """The reply to REQUEST, which is sent again every RESEND_SEC until one comes, as the
    supervisor does: a server drops its reply to a client whose reader it has not discovered
    yet (Fast DDS waits 100 ms, then logs "client will not receive response"), which a busy
    machine can make happen to a fresh client's first call although service_is_ready() said
    yes. Only one reply is taken; a resent request runs twice on the server."""
    spin_until(executor, client.service_is_ready, timeout, f"service {client.srv_name}")
    deadline = time.monotonic() + timeout
    futures = []
    while not any(f.done() for f in futures):
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out waiting for reply from {client.srv_name}")
        futures.append(client.call_async(request))
        resend = time.monotonic() + resend_sec
        while not any(f.done() for f in futures) and time.monotonic() < min(resend, deadline):
            executor.spin_once(timeout_sec=0.05)
    return next(f for f in futures if f.done()).result()


def ros_session(tmp_path_factory, domain: int, label: str):
    """Generator for a module's ROS fixture: its own ROS_DOMAIN_ID (no cross-talk with other
    modules), rclpy, an executor and node processes; afterwards every process is stopped, every
    participant destroyed and the domain restored. Yields (rclpy, executor, processes)."""
    saved = os.environ.get("ROS_DOMAIN_ID")
    os.environ["ROS_DOMAIN_ID"] = str(domain)
    import rclpy
    from econet_ros.nodes.runner import make_executor

    rclpy.init()
    procs = Processes(tmp_path_factory.mktemp(f"{label}-logs"))
    executor = make_executor()
    yield rclpy, executor, procs
    procs.stop_all()
    for node in list(executor.get_nodes()):     # leave no participant behind for later modules
        executor.remove_node(node)
        node.destroy_node()
    executor.shutdown()
    rclpy.try_shutdown()
    if saved is None:
        os.environ.pop("ROS_DOMAIN_ID", None)
    else:
        os.environ["ROS_DOMAIN_ID"] = saved
