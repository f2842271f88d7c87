"""Files in and out: inputs read as bounded regular files, outputs written atomically, one writer per path.

Every file tumble reads as a document (a scenario, a robot file, a CSV table) goes through
:func:`read_input`, and every file it writes through :func:`write_atomic` or :func:`write_atomic_all`
(the outputs of one command, renamed together at the end). An output is a new name or an existing regular
file (:func:`check_output`): writing by rename onto a symbolic link, a FIFO or a device would replace the
node itself (``-o /dev/null`` run as root replaced ``/dev/null``). Documented in ``docs/reliability.md``.
"""

from __future__ import annotations

import contextlib
import os
import re
import secrets
import shutil
import signal
import stat
import threading
from collections.abc import Callable, Iterator, Sequence


from tumble._validate import ValidationError

__all__ = ["MAX_INPUT_BYTES", "check_distinct", "check_output", "read_input", "require_regular", "write_atomic",
           "write_atomic_all"]

#: Largest input file read (64 MiB): a scenario or robot file is a few kB, an INS table of 500 000 rows
#: some 40 MB; past it a symbolic link to ``/dev/zero`` or a runaway file would be read into memory.
MAX_INPUT_BYTES = 64 * 2**20

_KINDS = ((stat.S_ISDIR, "a directory"), (stat.S_ISLNK, "a symbolic link"), (stat.S_ISFIFO, "a FIFO"),
          (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"))


def _kind(mode: int) -> str:
    """What a file of mode ``mode`` is, in words (``"a FIFO"``), for a file that is not a regular one."""
    return next((name for is_kind, name in _KINDS if is_kind(mode)), "not a regular file")


def _require_regular_mode(name: str, mode: int) -> None:
    """Refuse, naming ``name``, a file of mode ``mode`` that is not a regular file, saying what it is."""
    if not stat.S_ISREG(mode):
        raise ValidationError(f"{name}: not a regular file ({_kind(mode)}); give the path of a file")


def require_regular(path: str | os.PathLike) -> None:
    """Refuse (:class:`ValidationError` naming the path) an input that is not a regular file once symbolic
    links are followed: a FIFO would block the reader for ever, a device (``/dev/zero``) never end. For
    readers that open the path themselves (HDF5); :func:`read_input` checks the descriptor it reads."""
    _require_regular_mode(os.fspath(path), os.stat(path).st_mode)


def read_input(path: str | os.PathLike, *, limit: int = MAX_INPUT_BYTES) -> bytes:
    """The bytes of the input file ``path``: a regular file once symbolic links are followed, of at most
    ``limit`` bytes; anything else is refused with a :class:`ValidationError` naming the path and the rule.

    The file is opened without blocking and checked on the open descriptor, so a FIFO is refused at once
    instead of waiting for a writer, and nothing can be swapped in between the check and the read; at most
    ``limit + 1`` bytes are read, so a file that grows while it is read is refused too. A missing or
    unreadable path raises :class:`OSError`.
    """
    name = os.fspath(path)
    fd = os.open(name, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0))
    with open(fd, "rb", closefd=True) as handle:
        _require_regular_mode(name, os.fstat(fd).st_mode)
        data = handle.read(limit + 1)
    if len(data) > limit:
        raise ValidationError(f"{name}: larger than {limit} bytes, the most an input file may hold")
    return data


def check_output(path: str | os.PathLike, name: str) -> None:
    """Refuse an output path, naming ``name`` (an option such as ``--plot``, or the path itself), before
    anything is written: its directory missing (:class:`FileNotFoundError`) or not writable
    (:class:`PermissionError`, saying whether permission is denied or the file system is read-only), or a
    name that exists and is not a regular file — a directory, a symbolic link, a FIFO, a device
    (:class:`ValidationError`)."""
    path = os.fspath(path)
    directory = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(directory):
        raise FileNotFoundError(f"{name}: directory {directory!r} does not exist (writing {path!r})")
    if not os.access(directory, os.W_OK | os.X_OK):
        read_only = hasattr(os, "statvfs") and os.statvfs(directory).f_flag & os.ST_RDONLY
        reason = "read-only file system" if read_only else "permission denied"
        raise PermissionError(f"{name}: cannot write in directory {directory!r} ({reason})")
    try:
        mode = os.lstat(path).st_mode
    except FileNotFoundError:
        return
    if not stat.S_ISREG(mode):
        raise ValidationError(f"{name}: {path!r} is {_kind(mode)}; an output must be a new name or a regular file")


def _identity(path: str) -> tuple:
    """What two paths share when they name one file: the real directory and the name (or device and inode)."""
    try:
        st = os.stat(path)
    except FileNotFoundError:
        return (os.path.realpath(os.path.dirname(os.path.abspath(path))), os.path.basename(path))
    return (st.st_dev, st.st_ino)


def check_distinct(paths: Sequence[tuple[str, str | os.PathLike]]) -> None:
    """Refuse two of the ``(name, path)`` outputs of one command that are one file (the same name, a hard
    link, a path through another directory), naming both."""
    seen: dict[tuple, str] = {}
    for name, path in paths:
        key = _identity(os.fspath(path))
        if key in seen:
            raise ValidationError(f"{name}: {os.fspath(path)!r} is the same file as {seen[key]}; give each "
                                  "output its own name")
        seen[key] = name


def write_atomic(path: str | os.PathLike, write: Callable[[str], None]) -> None:
    """Write a file atomically: ``write(tmp_path)`` fills a temporary file, renamed onto ``path``.

    The temporary file ``.NAME.XXXXXXXX.tmp`` (8 hexadecimal digits) is made in the directory of ``path``,
    so :func:`os.replace` is an atomic rename: readers see either the old file or the complete new one,
    never a partial file. On any exception, including ``KeyboardInterrupt`` (SIGINT) and SIGTERM (turned
    into ``SystemExit(143)`` while the write runs, in the main thread), the temporary file is removed, a
    pre-existing ``path`` is left untouched, and the exception propagates. The new file gets the
    permissions of the file it replaces, or the default ``0o666 & ~umask``. ``path`` is checked first
    (:func:`check_output`): a new name or a regular file, in a directory that exists and can be written.

    One writer at a time: a writer holds an exclusive lock on the sibling ``.NAME.lock``
    (:class:`filelock.FileLock`: ``flock`` on POSIX, ``msvcrt.locking`` on Windows; removed when it is
    done; the operating system releases the lock of a killed process), and a second writer to the same
    path is refused at once with :class:`FileExistsError` naming it (it neither waits nor silently wins).
    Holding the lock, a writer removes the temporaries of ``path`` left by killed runs (``kill -9``),
    matching exactly its own pattern ``.NAME.XXXXXXXX.tmp``: no live writer owns them, and those of
    another file whose name begins with ``NAME`` are not touched.

    ``write`` must not infer the format from the file name, which ends in ``.tmp``: e.g.
    ``write_atomic("fig.png", lambda p: fig.savefig(p, format="png"))``.
    """
    write_atomic_all([(path, write)])


def write_atomic_all(writes: Sequence[tuple[str | os.PathLike, Callable[[str], None]]]) -> None:
    """Write several files as one: each ``(path, write)`` as by :func:`write_atomic`, every temporary file
    written first and all renamed at the end, so that a failure in any write leaves every ``path`` as it was.

    The paths are checked before anything is written (:func:`check_output`), and two that are one file
    are refused (:class:`ValidationError`).
    """
    targets = [(os.fspath(path), write) for path, write in writes]
    for path, _ in targets:
        check_output(path, path)
    check_distinct([(path, path) for path, _ in targets])
    temporaries: list[str] = []
    with contextlib.ExitStack() as held, _terminate_as_exit():
        for path, _ in targets:
            directory, name = os.path.split(os.path.abspath(path))
            held.enter_context(_exclusive(os.path.join(directory, f".{name}.lock"), path))
            _remove_stale(directory, name)
        try:
            for path, write in targets:
                temporaries.append(_new_temporary(path))
                _write_naming(path, write, temporaries[-1])
                _set_mode(temporaries[-1], path)
                _sync(temporaries[-1])  # the data reach the disk before the rename makes them visible
            for tmp_path, (path, _) in zip(temporaries, targets, strict=True):
                os.replace(tmp_path, path)
        except BaseException:
            for tmp_path in temporaries:
                with contextlib.suppress(FileNotFoundError):
                    os.remove(tmp_path)
            raise


def _write_naming(path: str, write: Callable[[str], None], tmp_path: str) -> None:
    """``write(tmp_path)``; an :class:`OSError` that names no file (a full disk: ``ENOSPC``) is raised again
    naming ``path``."""
    try:
        write(tmp_path)
    except OSError as exc:
        if exc.filename is not None or exc.errno is None:
            raise
        raise type(exc)(exc.errno, exc.strerror, path) from None


def _temporary_pattern(name: str) -> re.Pattern:
    """The names of the temporaries of the file ``name``, and of no other file: ``.NAME.`` 8 hexadecimal
    digits ``.tmp`` (the file ``NAME.x``'s would be ``.NAME.x.`` … ``.tmp``)."""
    return re.compile(rf"\.{re.escape(name)}\.[0-9a-f]{{8}}\.tmp")


def _new_temporary(path: str) -> str:
    """Create (exclusively, mode 0o600) and return a new temporary file beside ``path``, of its pattern."""
    directory, name = os.path.split(os.path.abspath(path))
    while True:
        tmp_path = os.path.join(directory, f".{name}.{secrets.token_hex(4)}.tmp")
        try:
            os.close(os.open(tmp_path, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0), 0o600))
        except FileExistsError:
            continue
        return tmp_path


def new_temporary_directory(path: str | os.PathLike) -> str:
    """Create and return a new empty directory beside ``path``, named as its temporaries are
    (``.NAME.XXXXXXXX.tmp``): a store written whole there, then renamed onto ``path``."""
    directory, name = os.path.split(os.path.abspath(path))
    while True:
        tmp_path = os.path.join(directory, f".{name}.{secrets.token_hex(4)}.tmp")
        try:
            os.mkdir(tmp_path, 0o700)
        except FileExistsError:
            continue
        return tmp_path


def _remove_stale(directory: str, name: str) -> None:
    """Remove the temporaries (files, or directories of a store) of ``directory/name`` that killed writers left
    (the caller holds its lock)."""
    pattern = _temporary_pattern(name)
    for entry in os.listdir(directory):
        if pattern.fullmatch(entry):
            stale = os.path.join(directory, entry)
            if os.path.isdir(stale) and not os.path.islink(stale):
                shutil.rmtree(stale, ignore_errors=True)
            else:
                with contextlib.suppress(FileNotFoundError):
                    os.remove(stale)


def _sync(path: str) -> None:
    """Flush the file ``path`` to the disk (``fsync``)."""
    fd = os.open(path, os.O_RDWR)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


@contextlib.contextmanager
def _exclusive(lock_path: str, path: str) -> Iterator[None]:
    """Hold an exclusive lock on ``lock_path`` (created, and removed after), or refuse: another writer has it."""
    import filelock  # imported when a file is first written: `import tumble` stays light

    lock = filelock.FileLock(lock_path, timeout=0, is_singleton=False)
    try:
        lock.acquire()
    except filelock.Timeout:
        raise FileExistsError(f"{path}: another process is writing it now (it holds {lock_path}); wait for it "
                              "to finish, or write elsewhere") from None
    except OSError as exc:  # the lock file cannot be made: say so, naming the output
        raise type(exc)(f"{path}: cannot create its lock file {lock_path} ({exc.strerror or exc})") from None
    try:
        yield
    finally:
        with contextlib.suppress(FileNotFoundError, PermissionError):  # Windows: a new holder has it open
            os.remove(lock_path)
        lock.release()


@contextlib.contextmanager
def _terminate_as_exit() -> Iterator[None]:
    """While the block runs in the main thread, SIGTERM raises ``SystemExit(143)`` (so cleanups run)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def exit_(signum, frame):
        raise SystemExit(128 + signal.SIGTERM)

    previous = signal.signal(signal.SIGTERM, exit_)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, signal.SIG_DFL if previous is None else previous)


def _set_mode(tmp_path: str, path: str) -> None:
    """Give ``tmp_path`` the permissions of ``path``, or those a plain ``open`` would give (the temporary
    is created readable by its owner only, 0o600)."""
    try:
        mode = stat.S_IMODE(os.stat(path).st_mode)
    except FileNotFoundError:
        umask = os.umask(0)  # the umask can only be read by setting it
        os.umask(umask)
        mode = 0o666 & ~umask
    os.chmod(tmp_path, mode)
