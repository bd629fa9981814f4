"""Which code made a result: the commit of the checkout this package runs from and whether its
tree had uncommitted changes, the versions of Python and of the packages that make the numbers,
and the time. Run folders record it for every session that writes into them (run_folders.py,
provenance.json); reports name it (made_with), and a pre-registered sweep's summary checks that
its registration commit precedes every run's commit (registration).

Git is asked once per process, with a timeout. Without git or a checkout (an installed package)
the commit is UNKNOWN: never an error. The result files themselves never hold any of this, so
that the same code makes them byte-identical whenever and wherever it runs. ROS-free."""
from __future__ import annotations

import functools
import json
import os
import platform
import re
import subprocess
from collections import Counter
from datetime import datetime, timezone
from importlib import metadata
from pathlib import Path

UNKNOWN = "unknown"
PACKAGES = ("numpy", "numba", "llvmlite", "scipy", "cma")     # those that make the numbers
GIT_TIMEOUT = 10.0      # seconds; a hung git (a network file system) must not hold a run up
CHECKOUT = Path(__file__).resolve().parent.parent               # when run from a checkout
# The code a sweep's driver ships to a Ray cluster's workers runs outside any checkout; the
# driver passes its own (commit, dirty) in this environment variable (sweeps/runner.py).
SHIPPED = "ECONET_SHIPPED_CODE"
COMMIT = re.compile(r"[0-9a-f]{7,40}")


def now() -> str:
    """The time, in UTC to the second (ISO 8601)."""
    return datetime.now(timezone.utc).isoformat(timespec="seconds")


@functools.cache
def code() -> dict:
    """This process's code: {"commit", "dirty", "versions", "platform"} (see docs/results-format.md,
    provenance.json)."""
    commit, dirty = git_state()
    if commit == UNKNOWN and os.environ.get(SHIPPED):
        commit, dirty = shipped_state(os.environ[SHIPPED])
    return {"commit": commit, "dirty": dirty, "versions": versions(),
            "platform": f"{platform.system()} {platform.machine()}"}


def shipped() -> str:
    """This process's (commit, dirty), for SHIPPED."""
    return json.dumps({"commit": code()["commit"], "dirty": code()["dirty"]})


def shipped_state(text: str) -> tuple[str, bool | None]:
    try:
        given = json.loads(text)
        commit, dirty = given["commit"], given["dirty"]
    except (ValueError, TypeError, KeyError):
        return UNKNOWN, None
    if not isinstance(commit, str) or not COMMIT.fullmatch(commit) or dirty not in (True, False):
        return UNKNOWN, None
    return commit, dirty


def git_state(checkout: Path = CHECKOUT) -> tuple[str, bool | None]:
    """(commit, dirty) of the git checkout whose top folder is ``checkout``; (UNKNOWN, None) when
    there is none (an installed package inside some other repository included) or git fails."""
    found = _git(checkout, "rev-parse", "--show-toplevel", "HEAD")
    lines = found.split("\n") if found is not None else []
    if len(lines) != 2 or Path(lines[0]).resolve() != Path(checkout).resolve():
        return UNKNOWN, None
    status = _git(checkout, "--no-optional-locks", "status", "--porcelain")
    return lines[1], None if status is None else bool(status)


def _git(checkout: Path, *args: str) -> str | None:
    """git's output, stripped; None when git is missing, fails or takes too long."""
    try:
        done = subprocess.run(["git", "-C", str(checkout), *args], capture_output=True,
                              text=True, timeout=GIT_TIMEOUT, check=False)
    except (OSError, subprocess.SubprocessError):
        return None
    return done.stdout.strip() if done.returncode == 0 else None


def versions() -> dict[str, str | None]:
    """Python's version and the installed versions of econet_ros and PACKAGES (None: not
    installed, or econet_ros run from a checkout without its build)."""
    found: dict[str, str | None] = {"python": platform.python_version()}
    for name in ("econet_ros", *PACKAGES):
        try:
            found[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            found[name] = None
    return found


@functools.cache
def is_ancestor(older: str, newer: str, checkout: Path = CHECKOUT) -> bool | None:
    """Whether commit ``older`` is an ancestor of (or is) commit ``newer`` in the checkout; None
    when that cannot be told (no checkout, or a commit it does not hold)."""
    if not (COMMIT.fullmatch(older) and COMMIT.fullmatch(newer)) or \
            git_state(checkout)[0] == UNKNOWN:
        return None
    try:
        done = subprocess.run(["git", "-C", str(checkout), "merge-base", "--is-ancestor", older,
                               newer], capture_output=True, timeout=GIT_TIMEOUT, check=False)
    except (OSError, subprocess.SubprocessError):
        return None
    return {0: True, 1: False}.get(done.returncode)


# -- what reports say ----------------------------------------------------------------------------
def named(commits: str, dirty: bool | None) -> str:
    """A run's or a report's code in words: its commits ("" when none was recorded), and
    whether any of them ran with uncommitted changes."""
    if not commits:
        return "no recorded commit (made before run folders recorded their code)"
    text = " then ".join("an unknown commit" if c == UNKNOWN else f"`{c[:12]}`"
                         for c in commits.split())
    return text + (" with uncommitted changes" if dirty else "")


def dirty_warning() -> list[str]:
    """A page's first line when this process runs from a tree with uncommitted changes: what
    such a tree makes cannot be re-made from any commit, so it is no result of record."""
    me = code()
    if not me["dirty"]:
        return []
    return [f"**Made from a tree with uncommitted changes** (at {named(me['commit'], False)}): "
            "not a result of record; re-make it from a clean tree.\n"]


def made_with(runs: list[tuple[str, bool | None]], registrations: list[str] = ()) -> str:
    """The line near a report's top on its code: the code that made the report, the code that
    made its runs ((commits, dirty) per run, as run_folders.run_code gives them), then the sentences
    on any registration (registration)."""
    me = code()
    counts = Counter(named(commits, dirty) for commits, dirty in runs).most_common()
    made = ", ".join(f"{name} ({count})" for name, count in counts) or "none"
    return " ".join([f"**Code**: this report was made with {named(me['commit'], me['dirty'])}; "
                     f"its {len(runs)} run(s) with {made}.", *filter(None, registrations)])


def registration(registered: str, runs: list[str], checkout: Path = CHECKOUT) -> str:
    """Whether a pre-registration's commit is an ancestor of every commit of every run (runs:
    each run's commits, space-separated), by the checkout, as a sentence."""
    def precedes(commits: str) -> bool | None:
        found = [is_ancestor(registered, c, checkout) for c in commits.split()] or [None]
        return False if False in found else None if None in found else True

    verdicts = Counter(precedes(commits) for commits in runs)
    text = (f"Pre-registered at commit `{registered[:12]}`, which is an ancestor of the commits "
            f"of {verdicts[True]} of its {len(runs)} run(s)")
    if verdicts[False]:
        text += f"; **not** of {verdicts[False]}"
    if verdicts[None]:
        text += (f"; {verdicts[None]} cannot be checked here (no recorded commit, or one this "
                 "checkout does not hold)")
    return text + "."
