"""One rule for every file chaoscam writes: checked first (:func:`check_output`, before any
work), never overwritten silently, written whole (:func:`atomic_path`: a temporary name beside
it, flushed, then renamed into place), locked against a second process (:class:`OutputLock`).
Every failure is an :class:`OutputError` (a ``ValueError``) naming the path and what to do (or,
for a write, an OSError naming the file)."""

from __future__ import annotations

import contextlib
import os
import threading
from collections.abc import Iterator
from pathlib import Path

__all__ = [
    "OutputError", "check_output", "atomic_path", "atomic_write_bytes", "OutputLock", "lock_all",
]  # fmt: skip


class OutputError(ValueError):
    """An output path cannot be written (missing folder, read-only, a directory, exists, or in
    use by another process)."""


def tmp_name(path: Path, tag: str = "") -> Path:
    """A temporary name beside ``path``, ``.tmp-PID[-TAG]-NAME``, keeping its suffix
    (matplotlib reads the format from it)."""
    extra = f"-{tag}" if tag else ""
    return path.with_name(f".tmp-{os.getpid()}{extra}-{path.name}")


def check_output(
    path: str | Path | None, *, flag: str = "--out", force: bool = False,
    suffixes: tuple[str, ...] | None = None, force_hint: str = "pass --force",
) -> Path | None:  # fmt: skip
    """Check that ``path`` can be written, before any work is done; returns it as a Path
    (None, no output asked for, passes).

    Parameters
    ----------
    flag : str
        How the path was given (``--out``, ``--section``, ...), for the message.
    force : bool
        Replace an existing file (``--force``); else an existing file is refused.
    suffixes : tuple of str, optional
        Allowed suffixes (case-insensitive), e.g. ``(".parquet", ".csv")``.
    force_hint : str
        How to replace an existing file, for the message (``pass replace=True`` in the API).

    Raises
    ------
    OutputError
        With the path and what to do.
    """
    if path is None:
        return None
    path = Path(path)
    if path.is_dir():  # first: "bad/" is a folder, whatever its suffix
        raise OutputError(f"{flag} {path}: is a directory; give a file name")
    if suffixes is not None and path.suffix.lower() not in suffixes:
        bare = path.name.lower() in suffixes  # ".html": a suffix without a name
        raise OutputError(
            f"{flag} {path}: the file must end in {' or '.join(suffixes)}"
            + (f" after a name (NAME{path.name})" if bare else "")
        )
    folder = path.parent if str(path.parent) else Path(".")
    if folder.exists() and not folder.is_dir():
        raise OutputError(f"{flag} {path}: {folder} is a file, not a folder")
    if not folder.is_dir():
        raise OutputError(f"{flag} {path}: the folder {folder} does not exist; create it first")
    _check_name_length(folder, path, flag)
    _probe(folder, f"{flag} {path}")
    if path.exists() or path.is_symlink():
        if not force:
            raise OutputError(
                f"{flag} {path} exists; nothing was overwritten: choose another name, or "
                f"{force_hint} to replace it"
            )
        # A dangling link is replaced like a file (os.replace swaps the name, not its target).
        if path.exists() and not os.access(path, os.W_OK):
            raise OutputError(f"{flag} {path}: exists and is read-only")
    return path


NAME_ROOM = 24
"""Bytes a file name must leave free for the names made from it: ``.tmp-PID-NAME.ckpt`` (an
atomic write or checkpoint folder on its way, PID up to 7 digits) is 18 longer."""


def _check_name_length(folder: Path, path: Path, flag: str) -> None:
    """Refuse, before any work, a name too long for the temporary and companion names."""
    try:
        most = os.pathconf(folder, "PC_NAME_MAX")
    except (OSError, ValueError, AttributeError):
        most = 255
    size = len(path.name.encode())
    if size > most - NAME_ROOM:
        raise OutputError(
            f"{flag} {path}: the file name is {size} bytes; at most {most - NAME_ROOM} here "
            f"({most} less {NAME_ROOM} for the temporary and companion names made from it)"
        )


def _probe(folder: Path, what: str) -> None:
    """Create and remove a file in ``folder``, the only sure test that it takes files
    (``os.access`` says yes to root on a read-only mount)."""
    probe = folder / f".tmp-{os.getpid()}-{threading.get_ident()}-probe"  # one per thread
    try:
        with open(probe, "x"):
            pass
    except OSError as err:
        raise OutputError(
            f"{what}: cannot write in the folder {folder} ({err.strerror or err})"
        ) from None
    with contextlib.suppress(OSError):
        probe.unlink()


@contextlib.contextmanager
def atomic_path(path: str | Path, *, replace: bool = True) -> Iterator[Path]:
    """A temporary path to write ``path`` to, flushed and moved into place when the block
    succeeds (the file is whole or absent whenever the process is killed), removed on an
    exception (an OSError then names ``path``). ``replace=False`` places it only if ``path``
    still does not exist, atomically (a hard link refuses an existing name): a file another
    process wrote meanwhile is kept, this one's result beside it (:func:`conflict_name`), and
    an :class:`OutputError` names both."""
    path = Path(path)
    tmp = tmp_name(path)
    try:
        yield tmp
        with open(tmp, "rb+") as fh:
            os.fsync(fh.fileno())
        if replace:
            os.replace(tmp, path)
        else:
            try:
                os.link(tmp, path)
            except FileExistsError:
                kept = conflict_name(path)
                os.replace(tmp, kept)
                raise OutputError(
                    f"{path} exists: another process wrote it while this run worked, or (a call "
                    "with replace=False) it was there before; it was not overwritten, and this "
                    f"run's result is in {kept}"
                ) from None
    except OSError as err:  # a full or failing disk: the file named, not a bare "[Errno 28]"
        why = f"cannot write {path}: {err.strerror or err}"
        raise (OSError(why) if err.errno is None else OSError(err.errno, why)) from None
    finally:
        with contextlib.suppress(OSError):
            tmp.unlink()


def conflict_name(path: Path) -> Path:
    """Where a result goes when ``path`` appeared meanwhile: ``NAME.PID.SUFFIX`` beside it."""
    return path.with_name(f"{path.stem}.{os.getpid()}{path.suffix}")


def write_new_parquet(table, path: str | Path, *, replace: bool = False) -> None:
    """A pyarrow ``table`` to ``path`` atomically (:func:`write_table`), refusing an existing
    file (unless ``replace``), a folder or a missing folder; a file object is written into."""
    from ._parquet import write_table

    if not isinstance(path, str | os.PathLike):  # a file object: pyarrow writes into it
        return write_table(table, path)
    path = check_output(path, flag="path", force=replace, force_hint="pass replace=True")
    with atomic_path(path, replace=replace) as tmp:
        write_table(table, tmp)


def atomic_write_bytes(path: str | Path, data: bytes, *, replace: bool = True) -> None:
    """Write ``data`` to ``path`` atomically (see :func:`atomic_path`)."""
    with atomic_path(path, replace=replace) as tmp:
        tmp.write_bytes(data)


class OutputLock:
    """An exclusive OS lock on ``path`` (``flock`` on a hidden ``.NAME.lock`` file beside it),
    taken without waiting (:class:`OutputError` when another process holds it) and released
    however the holder exits, so a killed run leaves no stale lock. A context manager;
    re-entrant within one thread for the same path, refused from another thread."""

    _held: dict[str, tuple[int, int]] = {}  # lock file -> (descriptor, thread that took it)
    _table = threading.Lock()

    def __init__(self, path: str | Path, what: str = "output") -> None:
        self.target = Path(path)
        named = self.target if self.target.name not in ("", "..") else self.target.resolve()
        if not named.name:
            raise OutputError(f"{path}: the root folder cannot be locked; choose a folder in it")
        self.path = named.with_name(f".{named.name}.lock")
        self.what = what
        self._fd: int | None = None
        self._nested = False

    def acquire(self) -> OutputLock:
        key = str(self.path.resolve())
        with OutputLock._table:
            if key in OutputLock._held:
                if OutputLock._held[key][1] != threading.get_ident():
                    raise OutputError(
                        f"{self.target} is in use by another thread of this process; wait "
                        f"for it to finish, or choose another {self.what}"
                    )
                self._nested = True  # this thread holds it already (an API call inside)
                return self
            return self._take(key)

    def _take(self, key: str) -> OutputLock:
        import fcntl

        while True:
            try:
                fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
            except FileNotFoundError:
                raise OutputError(
                    f"{self.target}: the folder {self.path.parent} does not exist; create it first"
                ) from None
            except OSError as err:
                raise OutputError(f"{self.target}: cannot create the lock file ({err})") from None
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                holder = os.pread(fd, 32, 0).decode(errors="replace").strip() or "?"
                os.close(fd)
                raise OutputError(
                    f"{self.target} is in use by another chaoscam process (pid {holder}); "
                    f"wait for it to finish, or choose another {self.what}"
                ) from None
            # the holder before us may have removed the file we opened: retry on the current one
            with contextlib.suppress(FileNotFoundError):
                if os.path.samestat(os.fstat(fd), os.stat(self.path)):
                    break
            os.close(fd)
        os.ftruncate(fd, 0)
        os.pwrite(fd, str(os.getpid()).encode(), 0)
        self._fd = fd
        OutputLock._held[key] = (fd, threading.get_ident())
        return self

    def release(self) -> None:
        if self._nested or self._fd is None:
            return
        with OutputLock._table:  # all of it: another thread must not open the dying file
            OutputLock._held.pop(str(self.path.resolve()), None)
            with contextlib.suppress(OSError):
                self.path.unlink()  # while still locked: a waiter re-checks the inode
            os.close(self._fd)
            self._fd = None

    __enter__ = acquire

    def __exit__(self, *exc) -> None:
        self.release()


@contextlib.contextmanager
def lock_all(paths, what: str = "output"):
    """:class:`OutputLock` on each of ``paths`` (a run's output and companions): a second
    process naming any of them is refused at its start, not the first run at its end."""
    paths = [Path(p) for p in paths]
    for path in paths:  # first: a lock's name (.NAME.lock) is longer than the name
        _check_name_length(path.parent, path, "--out")
    with contextlib.ExitStack() as stack:
        for path in paths:
            stack.enter_context(OutputLock(path, what))
        yield
