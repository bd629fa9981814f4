"""Writing files so that nothing finished is lost, and reading them back with one-line errors:
a folder's lock against a second writer, atomic replacement, rows appended and synced one by one
(CSV tables, .npy rows written in place), and full-disk or damage reported in one line naming the
file. Used by the run folders (run_folders.py), the study, sweeps, bags, the CLI and the supervisor;
knows nothing of what the files hold. ROS-free."""
from __future__ import annotations

import csv
import errno
import fcntl
import json
import os
import tempfile
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator

import numpy as np

from .errors import ResultsError, UsageError

LOCK_FILE = ".lock"
TEMPORARY_SUFFIX = ".tmp"      # write_atomically's temporary files: .<name>.<pid>.tmp
RESUME = ("the finished generations are kept: run the same command again to resume once this "
          "is fixed")


# -- writing safely ----------------------------------------------------------------------------
def ensure_writable(folder: Path) -> None:
    """Fail now, not after an hour of work, if results cannot be written to folder."""
    folder = Path(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=folder):
            pass
    except FileExistsError:
        raise UsageError(f"cannot write to output folder {folder}: a file has that name") \
            from None
    except OSError as error:
        raise UsageError(f"cannot write to output folder {folder}: "
                         f"{error.strerror or error}") from None


@contextmanager
def locked(folder: Path) -> Iterator[None]:
    """Hold ``folder``'s lock file while writing into it, so a second writer is refused at once
    in one line; the operating system drops the lock when this process ends, however it ends."""
    ensure_writable(folder)
    path = Path(folder) / LOCK_FILE
    with writing(path):
        handle = open(path, "a+", encoding="utf-8")
    with handle:
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            handle.seek(0)
            holder = handle.read().strip()
            raise UsageError(f"{folder} is being written by another econet process"
                             f"{f' (pid {holder})' if holder.isdigit() else ''}; wait for it "
                             "to finish or choose another output folder") from None
        with writing(path):
            handle.truncate(0)
            handle.write(f"{os.getpid()}\n")
            handle.flush()
        yield


@contextmanager
def writing(path: Path, then: str = "") -> Iterator[None]:
    """Turn an OSError while writing ``path`` into one line for the user (UsageError) that says
    so when the disk is full; ``then`` adds what the user can do about it."""
    try:
        yield
    except OSError as error:
        if error.errno in (errno.ENOSPC, errno.EDQUOT):
            message = f"disk full: cannot write {path}"
        else:
            message = f"cannot write {path}: {error.strerror or error}"
        raise UsageError(f"{message}; {then}" if then else message) from None


def write_atomically(path: Path, text: str) -> None:
    """Replace ``path`` by ``text`` all at once (a temporary file, synced, renamed over it): a
    kill or a full disk leaves the old file or the new one, never a torn one (but a kill may
    leave the temporary file: remove_torn_writes)."""
    path = Path(path)
    temporary = path.with_name(f".{path.name}.{os.getpid()}{TEMPORARY_SUFFIX}")
    with writing(path):
        try:
            with open(temporary, "w", encoding="utf-8", newline="") as handle:
                handle.write(text)
                handle.flush()
                os.fsync(handle.fileno())
            os.replace(temporary, path)
        finally:
            temporary.unlink(missing_ok=True)


def remove_torn_writes(folder: Path) -> None:
    """Delete the temporary files that atomic writes into ``folder`` killed midway left behind
    (.<name>.<pid>.tmp). Only while holding the folder's lock: then nobody is writing one."""
    for temporary in Path(folder).glob(f".*{TEMPORARY_SUFFIX}"):
        if temporary.name.rsplit(".", 2)[1].isdigit():
            temporary.unlink(missing_ok=True)


# -- tables written row by row (metrics.csv, behaviour.csv) -----------------------------------
def start_table(path: Path, columns: list[str]) -> None:
    write_atomically(path, ",".join(columns) + "\r\n")     # csv's own line ending


def append_row(path: Path, values: list) -> None:
    """Append one row and sync it. A row records that its generation is complete, so it is
    written last; one torn by a crash is cut off before the next append (cut_table)."""
    with writing(path, then=RESUME), open(path, "a", newline="", encoding="utf-8") as handle:
        csv.writer(handle).writerow(values)
        handle.flush()
        os.fsync(handle.fileno())


def table_rows(path: Path, columns: list[str]) -> np.ndarray:
    """A table's complete rows as numbers, shaped (rows, columns); a torn last line (a write cut
    short) is not a complete row. ResultsError names the file and what is wrong with it."""
    try:
        text = path.read_bytes().decode("utf-8")
    except FileNotFoundError:
        raise ResultsError(f"{path} is missing") from None
    except OSError as error:
        raise ResultsError(f"cannot read {path}: {error.strerror or error}") from None
    except UnicodeDecodeError:
        raise ResultsError(f"{path} is damaged (not text)") from None
    lines = text[:text.rfind("\n") + 1].splitlines()
    if not lines or lines[0].split(",") != columns:
        raise ResultsError(f"{path} has columns from another version, or is damaged")
    rows = np.empty((len(lines) - 1, len(columns)))
    for number, line in enumerate(lines[1:], start=2):
        values = [_number(field) for field in line.split(",")]
        if len(values) != len(columns) or None in values:
            raise ResultsError(f"{path} is damaged: line {number} is {line[:40]!r}, not "
                               f"{len(columns)} numbers")
        rows[number - 2] = values
    return rows


def _number(text: str) -> float | None:
    try:
        return float(text)
    except ValueError:
        return None


def cut_table(path: Path, rows: int) -> None:
    """Cut a table back to its header and first ``rows`` rows, dropping a torn last line, in
    place: the rows kept keep their exact bytes."""
    data = path.read_bytes()
    end = -1
    for _ in range(rows + 1):
        end = data.index(b"\n", end + 1)
    if end + 1 < len(data):
        with writing(path, then=RESUME):
            os.truncate(path, end + 1)


class RowWriter:
    """Writes whole rows of one .npy file in place, with pwrite rather than through a memory
    map: storing into a map on a full disk kills the process (SIGBUS). The file's whole space
    is reserved on opening, so a full disk shows up then, as an OSError."""

    def __init__(self, path: Path, array: np.ndarray):
        self.dtype = array.dtype
        self.offset = array.offset
        self.row_bytes = array[0].nbytes
        self.fd = os.open(path, os.O_RDWR)
        try:
            os.posix_fallocate(self.fd, 0, array.offset + array.nbytes)
        except OSError:
            os.close(self.fd)
            raise

    def __enter__(self) -> "RowWriter":
        return self

    def __exit__(self, *failure) -> None:
        os.close(self.fd)

    def write(self, row: int, values: np.ndarray) -> None:
        data = np.ascontiguousarray(values, dtype=self.dtype).tobytes()
        if os.pwrite(self.fd, data, self.offset + row * self.row_bytes) != len(data):
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    def sync(self) -> None:
        os.fdatasync(self.fd)


# -- reading back --------------------------------------------------------------------------------
def read_json_object(path: Path) -> dict:
    """A JSON object stored in a result folder, or ResultsError saying what is wrong with it."""
    try:
        data = json.loads(Path(path).read_bytes())
    except OSError as error:
        raise ResultsError(f"cannot read {path}: {error.strerror or error}") from None
    except ValueError as error:
        raise ResultsError(f"{path} is damaged (empty, torn or not JSON: {error})") from None
    if not isinstance(data, dict):
        raise ResultsError(f"{path} is damaged (not a JSON object)")
    return data


def stored_whole_number(data: dict, key: str, low: int, source: Path) -> int:
    """data[key] when it is a whole number of at least ``low``, else ResultsError."""
    value = data.get(key)
    if isinstance(value, bool) or not isinstance(value, int) or value < low:
        raise ResultsError(f"{source} is damaged: {key} must be a whole number of at least "
                           f"{low}, got {value!r}")
    return value
