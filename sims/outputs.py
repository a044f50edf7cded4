"""Outputs of a run or a plan: validated up front, staged, swapped into place whole.

The contract (README, "Outputs and interrupts"):

- planbench replaces an output directory only if planbench wrote it: the directory holds
  ``planbench-manifest.json`` and nothing that the manifest does not list. An empty directory
  may be filled. Everything else is refused before any work starts, as are ``.``, ``..`` and
  every other directory that holds the current one, ``/``, the home directory, the empty
  string, an existing file or symbolic link, places where nothing can be created (``/proc``,
  read-only or immutable directories) and names or paths longer than the file system allows.
- A video outside the output directory may replace only a video that planbench wrote (its
  container's ``comment`` tag says so); its suffix must be one of VIDEO_SUFFIXES.
- Writing happens in a staging directory ``.planbench-tmp-*`` beside the target, which is
  swapped with the old directory by one ``renameat2(RENAME_EXCHANGE)``: a reader of
  ``out/summary.json`` finds either the old file or the new one at every instant. Where the
  file system cannot exchange, each file is moved in by ``os.replace`` instead (still never
  missing), and the old files the old manifest lists are removed after.
- One run at a time per target: a lock file ``.planbench-lock-*`` beside it (``flock``, freed
  by the kernel when its process dies) refuses a second writer with exit 2.
- Leftovers of a killed run (SIGKILL mid-write) are staging directories that name their
  target in a marker or in a planbench manifest; the next run into that target, holding its
  lock, removes them. Anything else is left alone.
- A failure or an interrupt removes the staging directory, the lock file and any parent
  directory created for the output, and leaves the old output as it was.
"""

from __future__ import annotations

import contextlib
import ctypes
import errno
import fcntl
import hashlib
import json
import os
import re
import shutil
import signal
import subprocess
import tempfile
import time
import zipfile
from pathlib import Path

import numpy as np

MANIFEST = "planbench-manifest.json"
STAGING_PREFIX = ".planbench-tmp-"
STAGING_MARKER = ".planbench-staging.json"
LOCK_PREFIX = ".planbench-lock-"
PROBE_PREFIX = ".planbench-probe-"
#: Containers that carry H.264 and that the ffmpeg of imageio-ffmpeg writes (tested).
VIDEO_SUFFIXES = (".mp4", ".m4v", ".mov", ".mkv")
#: The ``comment`` tag of every video planbench writes: the proof that it may replace it.
VIDEO_TAG = "written by planbench"
#: Files of a run directory, and of a plan directory (more may follow, e.g. videos).
RUN_FILES = ("summary.json", "timeseries.npz", "report.png", "log.arrow", MANIFEST)
PLAN_FILES = ("plan.npz", "plan.png", MANIFEST)
#: Longest name planbench writes inside an output directory besides a video's.
_LONGEST_INNER = max(
    len(n)
    for n in (*RUN_FILES, *PLAN_FILES, "segments.json", "figures.png", "methods.png", "methods.npz", STAGING_MARKER)
)
_RENAME_EXCHANGE = 2
_AT_FDCWD = -100
#: The signals that interrupt a run (the CLI turns them into exit 128 + signal).
INTERRUPT_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


class RunStopped(KeyboardInterrupt):
    """SIGTERM in a supervised run (its time limit passed, ``planbench.supervise``): its staging
    directory keeps the log streamed so far (``partial_log``) while the rest is removed."""


class OutputError(ValueError):
    """The output location cannot or may not be written (bad input: exit 2)."""


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("planbench")
    except PackageNotFoundError:
        return "unknown"


@contextlib.contextmanager
def signals_deferred():
    """Hold back SIGINT, SIGTERM and SIGHUP: a step in here (a swap, a clean-up) completes,
    and a signal that came meanwhile is delivered right after."""
    old = signal.pthread_sigmask(signal.SIG_BLOCK, INTERRUPT_SIGNALS)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


def _usual_mode(path: Path, mode: int) -> None:
    """mkdtemp/mkstemp make private entries (0700/0600); give ``path`` ``mode`` less the umask."""
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(path, mode & ~umask)


def _nearest_existing(path: Path) -> Path:
    parent = path.parent
    while not os.path.lexists(parent):
        parent = parent.parent
    return parent


def _check_lengths(what: str, path: Path, deepest_inner: int) -> None:
    """Every component within NAME_MAX and the deepest file within PATH_MAX (bytes)."""
    anchor = _nearest_existing(path)
    try:
        name_max = os.pathconf(anchor, "PC_NAME_MAX")
        path_max = os.pathconf(anchor, "PC_PATH_MAX")
    except OSError:
        name_max, path_max = 255, 4096
    for part in path.parts[1:]:
        n = len(os.fsencode(part))
        if n > name_max:
            shown = part if len(part) <= 40 else part[:37] + "..."
            raise OutputError(
                f"{what} {shown!r}: a name of {n} bytes, longer than the file system's limit of {name_max}"
            )
    staging = len(STAGING_PREFIX) + 8
    n = len(os.fsencode(str(path.parent))) + 1 + max(len(os.fsencode(path.name)), staging) + 1 + deepest_inner
    if n >= path_max:
        raise OutputError(
            f"{what} {str(path)[:40]}...: its files' paths would be {n} bytes, "
            f"longer than the file system's limit of {path_max - 1}"
        )


def _probe(what: str, path: Path) -> None:
    """Create (and remove) a directory and a file where ``path`` will be created."""
    anchor = _nearest_existing(path)
    if not anchor.is_dir():
        raise OutputError(f"{what} {path}: {anchor} is not a directory")
    try:
        probe = tempfile.mkdtemp(prefix=PROBE_PREFIX, dir=anchor)
    except OSError as e:
        raise OutputError(f"{what} {path}: nothing can be created in {anchor} ({e.strerror or e})") from None
    try:
        with open(os.path.join(probe, "probe"), "wb") as f:
            f.write(b"planbench")
    except OSError as e:
        raise OutputError(f"{what} {path}: files cannot be written in {anchor} ({e.strerror or e})") from None
    finally:
        shutil.rmtree(probe, ignore_errors=True)


def _absolute(raw, what: str, option: str) -> Path:
    if raw is None or str(raw).strip() == "":
        raise OutputError(f"{what} {str(raw or '')!r} is empty; give {option} a path")
    if "\0" in str(raw):
        raise OutputError(f"{what} {str(raw)!r} contains a NUL byte")
    return Path(os.path.abspath(os.path.expanduser(str(raw))))


def _safe_relative(name) -> bool:
    """A path a manifest may list: relative, inside its directory (no '..', no root)."""
    if not isinstance(name, str) or not name or "\0" in name:
        return False
    path = Path(name)
    return not path.is_absolute() and ".." not in path.parts


def read_manifest(directory: Path) -> dict | None:
    """The manifest of a directory planbench wrote, or None if there is none, it is not one,
    or it lists a path outside its directory (which planbench never writes)."""
    try:
        manifest = json.loads((Path(directory) / MANIFEST).read_text())
    except (OSError, ValueError, UnicodeDecodeError):
        return None
    if (
        not isinstance(manifest, dict)
        or manifest.get("written_by") != "planbench"
        or not isinstance(manifest.get("files"), list)
        or not all(_safe_relative(f) for f in manifest["files"])
    ):
        return None
    return manifest


def _foreign_entries(directory: Path) -> list[str] | None:
    """What in ``directory`` planbench did not write: [] for an empty directory or one whose
    every entry its manifest lists; None when it has entries and no (valid) manifest. A
    symbolic link is always foreign: planbench writes none, and deleting "through" one could
    reach a file outside."""
    files, dirs = _entries(directory)
    if not files and not dirs:
        return []
    manifest = read_manifest(directory)
    if manifest is None:
        return None
    listed = set(manifest["files"]) | {MANIFEST}
    parents = {p.as_posix() for f in listed for p in Path(f).parents}
    links = {e for e in files + dirs if os.path.islink(directory / e)}
    return sorted({f for f in files if f not in listed} | {d for d in dirs if d not in parents} | links)


def _remove_listed(root: Path, names) -> None:
    """Delete the files ``names`` (relative paths) inside ``root``, then the folders that held
    them once empty. A name is skipped if anything on its way is a symbolic link (the link
    could lead outside ``root``) or it is not a regular file."""
    folders = set()
    for name in names:
        path = root / name
        steps = [root / Path(*Path(name).parts[:k]) for k in range(1, len(Path(name).parts))]
        if any(os.path.islink(p) for p in steps) or os.path.islink(path) or not path.is_file():
            continue
        with contextlib.suppress(OSError):
            path.unlink()
            folders.update(steps)
    for folder in sorted(folders, key=lambda p: len(p.parts), reverse=True):
        with contextlib.suppress(OSError):
            folder.rmdir()  # only if empty


def _shown(names: list[str]) -> str:
    return ", ".join(names[:3]) + (", ..." if len(names) > 3 else "")


def _discard_old_output(old: Path, target: Path) -> None:
    """Remove a replaced output directory ``old``: only the files its manifest lists, then its
    emptied directories. Anything else (a file added after the last check) is kept: the
    directory is renamed, visibly, to ``TARGET.kept-<UTC time>`` beside the target, less the
    manifest, so that nothing ever takes it for planbench's again."""
    manifest = read_manifest(old) or {"files": []}
    _remove_listed(old, [f for f in manifest["files"] if f != MANIFEST] + [MANIFEST])
    try:
        old.rmdir()
    except OSError:
        stamp = time.strftime("%Y%m%dT%H%M%SZ", time.gmtime())
        os.rename(old, target.with_name(f"{target.name}.kept-{stamp}"))


def _entries(directory: Path) -> tuple[list[str], list[str]]:
    """(files, directories) below ``directory`` as relative POSIX paths."""
    files, dirs = [], []
    for root, dirnames, filenames in os.walk(directory):
        rel = Path(root).relative_to(directory)
        dirs += [(rel / d).as_posix() for d in dirnames]
        files += [(rel / f).as_posix() for f in filenames]
        # symbolic links to directories are listed (os.walk does not follow them)
    return files, dirs


class _Target:
    """What the output directory and an outside video share: the parents created for them,
    and their lock."""

    what = "output"

    def __init__(self, raw, option: str):
        self.option = option
        self.path = _absolute(raw, self.what, option)
        self._lock_fd: int | None = None
        self._created: list[Path] = []

    def __str__(self) -> str:
        return str(self.path)

    @property
    def is_reserved(self) -> bool:
        return self._lock_fd is not None

    @contextlib.contextmanager
    def reserved(self):
        """Create missing parents, lock the target, remove provable leftovers. On an
        exception the parents created here are removed again (if still empty)."""
        ok = False
        try:
            self._make_parents()
            self._lock_fd = _acquire_lock(self.path, self.what, self.option)
            remove_leftovers(self.path)
            yield self
            ok = True
        finally:
            with signals_deferred():
                if self._lock_fd is not None:
                    _release_lock(self.path, self._lock_fd)
                    self._lock_fd = None
                if not ok:
                    for d in reversed(self._created):
                        with contextlib.suppress(OSError):
                            d.rmdir()
                self._created = []

    def _make_parents(self) -> None:
        missing = []
        parent = self.path.parent
        while not os.path.lexists(parent):
            missing.append(parent)
            parent = parent.parent
        for d in reversed(missing):
            try:
                d.mkdir()
            except FileExistsError:
                continue
            except OSError as e:
                raise OutputError(f"{self.what} {self.path}: cannot create {d} ({e.strerror or e})") from None
            self._created.append(d)


def _refuse_place(what: str, path: Path) -> None:
    """The directories no output may replace or fill: the root, the current directory and
    every directory that holds it, the home directory."""
    real = Path(os.path.realpath(path))
    cwd = Path(os.path.realpath(os.getcwd()))
    if real == Path(real.anchor):
        raise OutputError(f"{what} {path} is the file system's root; choose a new directory")
    if real == cwd:
        raise OutputError(f"{what} {path} is the current directory; choose a new directory")
    if cwd.is_relative_to(real):
        raise OutputError(f"{what} {path} holds the current directory; choose a new directory")
    if real == Path(os.path.realpath(Path.home())):
        raise OutputError(f"{what} {path} is the home directory; choose a new directory")


def _written_by_planbench(entry: Path) -> bool:
    """Whether an entry of a directory of outputs is planbench's: an output directory (its
    manifest), a campaign directory (its state file), a lock, staging or probe entry, or a
    video with planbench's tag."""
    if entry.name.startswith((LOCK_PREFIX, STAGING_PREFIX, PROBE_PREFIX)):
        return True
    if entry.is_symlink():
        return False
    if entry.is_dir():
        return read_manifest(entry) is not None or (entry / CAMPAIGN_STATE).is_file()
    return entry.is_file() and entry.suffix.lower() in VIDEO_SUFFIXES and is_planbench_video(entry)


#: A campaign directory's state file (planbench.campaign.store.STATE).
CAMPAIGN_STATE = "planbench-campaign.json"


class OutputRoot:
    """A directory of output directories (``demo --out``: one directory per scenario inside).

    The same places are refused as for an OutputDir (the root, the current directory or one
    that holds it, the home directory, the empty string, a file, a symbolic link, names too
    long). An existing directory may hold only what planbench wrote: output and campaign
    directories, planbench's lock and staging entries and its videos (``planbench run``'s
    default ``results/NAME`` and a sweep's ``results/SPEC`` live there too). ``inner``: the
    names of the output directories the caller validates itself, each an OutputDir.
    Nothing is written here; the first OutputDir reserved inside creates the directory.
    """

    what = "output dir"

    def __init__(self, raw, option: str, inner=()):
        self.option = option
        self.path = path = _absolute(raw, self.what, option)
        _refuse_place(self.what, path)
        longest = max([len(os.fsencode(n)) for n in inner] + [0])
        _check_lengths(self.what, path, longest + 1 + len(STAGING_PREFIX) + 8 + 1 + _LONGEST_INNER)
        if os.path.islink(path):
            raise OutputError(f"{self.what} {path} is a symbolic link; give the directory itself")
        if not os.path.lexists(path):
            return
        if not path.is_dir():
            raise OutputError(f"{self.what} {path} exists and is not a directory")
        try:
            names = sorted(os.listdir(path))
        except OSError as e:
            raise OutputError(f"{self.what} {path} cannot be read ({e.strerror or e})") from None
        foreign = [n for n in names if n not in inner and not _written_by_planbench(path / n)]
        if foreign:
            raise OutputError(
                f"{self.what} {path} holds files planbench did not write ({_shown(foreign)}); "
                f"choose another {option} or move them away"
            )

    def __str__(self) -> str:
        return str(self.path)

    def __truediv__(self, name: str) -> Path:
        return self.path / name


class OutputDir(_Target):
    """A directory that planbench writes whole (``--out`` of ``run`` and ``plan``, and each
    scenario's directory of ``demo``).

    ``OutputDir(raw)`` validates without writing anything (raises OutputError);
    ``with target.reserved():`` creates missing parents, takes the lock and removes
    provable leftovers; ``with target.staging() as tmp:`` yields the staging directory and
    swaps it in when the block ends without an exception.
    """

    what = "output dir"

    def __init__(self, raw, option: str = "--out", kind: str = "run"):
        super().__init__(raw, option)
        self.kind = kind
        path, what = self.path, self.what
        _refuse_place(what, path)
        _check_lengths(what, path, _LONGEST_INNER)
        if os.path.islink(path):
            raise OutputError(f"{what} {path} is a symbolic link; give the directory itself")
        if os.path.lexists(path):
            if not path.is_dir():
                raise OutputError(f"{what} {path} exists and is not a directory")
            self._check_replaceable()
            if not os.access(path, os.W_OK | os.X_OK):
                raise OutputError(f"{what} {path} cannot be replaced: it is not writable (read-only or immutable)")
        _probe(what, path)

    def _check_replaceable(self) -> None:
        foreign = _foreign_entries(self.path)
        if foreign is None:
            raise OutputError(
                f"{self.what} {self.path} is not empty and planbench did not write it (no "
                f"{MANIFEST}); choose another {self.option} or empty it yourself"
            )
        if foreign:
            raise OutputError(
                f"{self.what} {self.path} holds files planbench did not write "
                f"({_shown(foreign)}); choose another {self.option} or move them away"
            )

    @contextlib.contextmanager
    def staging(self, info: dict | None = None):
        """Yield a new staging directory; on success write the manifest and swap it in.
        Reserves the target first unless the caller already did."""
        if not self.is_reserved:
            with self.reserved(), self.staging(info) as tmp:
                yield tmp
            return
        tmp = _new_staging(self.path.parent, self.path.name)
        try:
            yield tmp
            with signals_deferred():
                files = [f for f in _entries(tmp)[0] if f != STAGING_MARKER]
                manifest = {
                    "written_by": "planbench",
                    "version": _version(),
                    "kind": self.kind,
                    "target": self.path.name,
                    "files": sorted(files + [MANIFEST]),
                    "written_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
                    **(info or {}),
                }
                (tmp / MANIFEST).write_text(json.dumps(manifest, indent=1) + "\n")
                (tmp / STAGING_MARKER).unlink()
                _usual_mode(tmp, 0o777)
                self._check_unchanged(tmp)
                swap_in(tmp, self.path)
        except BaseException as e:
            with signals_deferred():
                if isinstance(e, RunStopped):  # the log so far stays, for partial_log
                    _remove_all_but(tmp, ("log.arrow", STAGING_MARKER))
                else:
                    shutil.rmtree(tmp, ignore_errors=True)
            raise

    def _check_unchanged(self, tmp: Path) -> None:
        """Just before the swap: if files planbench did not write appeared in the target
        while it ran, keep them and the target as they are, move this run's output beside it
        (``TARGET.new-<UTC time>``) and refuse."""
        if not os.path.lexists(self.path):
            return
        foreign = (
            _foreign_entries(self.path) if self.path.is_dir() and not self.path.is_symlink() else ["(not a directory)"]
        )
        if foreign is None or foreign:
            stamp = time.strftime("%Y%m%dT%H%M%SZ", time.gmtime())
            kept = self.path.with_name(f"{self.path.name}.new-{stamp}")
            manifest = json.loads((tmp / MANIFEST).read_text())
            manifest["target"] = kept.name
            (tmp / MANIFEST).write_text(json.dumps(manifest, indent=1) + "\n")
            os.rename(tmp, kept)
            what = "files planbench did not write" if foreign is None else f"{_shown(foreign)}"
            raise OutputError(
                f"{self.what} {self.path} gained {what} during the run; it was left "
                f"as it is and this run's output is in {kept}"
            )


def _remove_all_but(folder: Path, keep: tuple) -> None:
    """Remove what ``folder`` holds but the entries named ``keep``."""
    for entry in folder.iterdir():
        if entry.name not in keep:
            if entry.is_dir() and not entry.is_symlink():
                shutil.rmtree(entry, ignore_errors=True)
            else:
                with contextlib.suppress(OSError):
                    entry.unlink()


def _new_staging(parent: Path, target_name: str) -> Path:
    """A staging directory in ``parent`` whose marker names ``target_name`` (and this process)."""
    with signals_deferred():
        tmp = Path(tempfile.mkdtemp(prefix=STAGING_PREFIX, dir=parent))
        marker = json.dumps({"written_by": "planbench", "target": target_name, "pid": os.getpid()})
        fd = os.open(tmp / STAGING_MARKER, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644)
        try:
            os.write(fd, marker.encode())
        finally:
            os.close(fd)
    return tmp


def _exchange(a: Path, b: Path) -> bool:
    """Swap two directory entries atomically (Linux renameat2 RENAME_EXCHANGE); False where the
    C library or the file system cannot."""
    libc = ctypes.CDLL(None, use_errno=True)
    renameat2 = getattr(libc, "renameat2", None)
    if renameat2 is None:
        return False
    if renameat2(_AT_FDCWD, os.fsencode(a), _AT_FDCWD, os.fsencode(b), _RENAME_EXCHANGE) == 0:
        return True
    code = ctypes.get_errno()
    if code in (errno.EINVAL, errno.ENOSYS, errno.ENOTSUP, errno.EOPNOTSUPP):
        return False
    raise OSError(code, os.strerror(code), str(b))


#: Tests set this to False to exercise the per-file fallback.
USE_EXCHANGE = True


def swap_in(tmp: Path, target: Path) -> None:
    """Make the staging directory ``tmp`` the directory ``target``.

    A reader of any file of the new output finds, at every instant, the old file or the new
    one. The old directory (if any) is removed after.
    """
    if not os.path.lexists(target):
        os.rename(tmp, target)
        return
    if not any(target.iterdir()):
        os.rename(tmp, target)  # rename replaces an empty directory atomically
        return
    if USE_EXCHANGE and _exchange(tmp, target):
        _discard_old_output(tmp, target)  # tmp now holds the old output
        return
    # Per file: move each new file over the old one, then drop the old ones not rewritten.
    old = read_manifest(target) or {"files": []}
    new_files, new_dirs = _entries(tmp)
    for d in sorted(new_dirs):
        (target / d).mkdir(exist_ok=True)
    for f in sorted(new_files, key=lambda f: f == MANIFEST):  # the manifest last
        os.replace(tmp / f, target / f)
    _remove_listed(target, [f for f in old["files"] if f not in new_files])
    shutil.rmtree(tmp)


def _owned_leftover(entry: Path, target_name: str) -> bool:
    """Whether ``entry`` (a staging or probe directory) provably belongs to planbench's run
    into ``target_name``: its marker or its manifest names it (a probe: it holds at most the
    probe file)."""
    if entry.name.startswith(PROBE_PREFIX):
        with contextlib.suppress(OSError):
            return {p.name for p in entry.iterdir()} <= {"probe"}
        return False
    for marker in (STAGING_MARKER, MANIFEST):
        try:
            content = json.loads((entry / marker).read_text())
        except (OSError, ValueError, UnicodeDecodeError):
            continue
        if (
            isinstance(content, dict)
            and content.get("written_by") == "planbench"
            and content.get("target") == target_name
        ):
            return True
    return False


#: An empty staging directory this old (s) is a killed run's, not one being set up now.
EMPTY_LEFTOVER_AGE_S = 60.0


def remove_leftovers(target: Path) -> list[Path]:
    """Remove what a killed run into ``target`` left beside it: staging directories whose
    marker or manifest names ``target``, probes, and staging directories left empty for
    over EMPTY_LEFTOVER_AGE_S. Call with the target's lock held, so that no live run owns
    them. Anything else is left alone. Returns what was removed."""
    removed = []
    with contextlib.suppress(OSError):
        for entry in target.parent.iterdir():
            if not entry.name.startswith((STAGING_PREFIX, PROBE_PREFIX)) or entry.is_symlink() or not entry.is_dir():
                continue
            if _owned_leftover(entry, target.name):
                if (entry / STAGING_MARKER).exists() or entry.name.startswith(PROBE_PREFIX):
                    shutil.rmtree(entry, ignore_errors=True)  # only ever written by planbench
                else:  # an old output swapped out: its listed files only
                    _discard_old_output(entry, target)
                removed.append(entry)
            elif not any(entry.iterdir()) and time.time() - entry.stat().st_mtime > EMPTY_LEFTOVER_AGE_S:
                with contextlib.suppress(OSError):
                    entry.rmdir()
                    removed.append(entry)
    return removed


def partial_log(target: Path, name: str = "log.arrow") -> Path | None:
    """The log a run into ``target`` that ended without completing streamed, in its staging
    directory beside ``target`` (the newest such, its marker naming ``target``), or None.
    Call with the target's lock held (no live run owns a staging directory then)."""
    found = []
    with contextlib.suppress(OSError):
        for entry in target.parent.iterdir():
            if (
                entry.name.startswith(STAGING_PREFIX)
                and not entry.is_symlink()
                and entry.is_dir()
                and (entry / STAGING_MARKER).is_file()
                and _owned_leftover(entry, target.name)
            ):
                log = entry / name
                if log.is_file() and not log.is_symlink():
                    found.append((log.stat().st_mtime, log))
    return max(found)[1] if found else None


def _lock_path(target: Path) -> Path:
    digest = hashlib.sha256(os.fsencode(target.name)).hexdigest()[:16]
    return target.parent / f"{LOCK_PREFIX}{digest}"


def _acquire_lock(target: Path, what: str, option: str) -> int:
    """flock a lock file beside ``target``; a second planbench writer is refused."""
    path = _lock_path(target)
    while True:
        try:
            fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as e:
            raise OutputError(f"{what} {target}: cannot create its lock file ({e.strerror or e})") from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.pread(fd, 64, 0).decode(errors="replace").strip() or "?"
            os.close(fd)
            raise OutputError(
                f"{what} {target} is being written by another planbench run "
                f"(pid {holder}); wait for it or choose another {option}"
            ) from None
        # The file may have been unlinked by the previous holder between open and flock.
        try:
            same = os.stat(path).st_ino == os.fstat(fd).st_ino
        except FileNotFoundError:
            same = False
        if same:
            os.ftruncate(fd, 0)
            os.pwrite(fd, str(os.getpid()).encode(), 0)
            return fd
        os.close(fd)


def _release_lock(target: Path, fd: int) -> None:
    with contextlib.suppress(OSError):
        os.unlink(_lock_path(target))
    os.close(fd)


class VideoFile(_Target):
    """A video written outside an output directory (``--video``), or inside one.

    Inside ``out_dir`` it is rendered into the output's staging directory and ``relative``
    is its path there; outside, it gets a staging directory and a lock of its own, and may
    replace only a video that planbench wrote.
    """

    what = "video"

    def __init__(self, raw, out_dir: OutputDir | None = None, reserved_names=RUN_FILES, option: str = "--video"):
        super().__init__(raw, option)
        self.relative: Path | None = None
        self._staged: Path | None = None
        path = self.path
        if path.suffix.lower() not in VIDEO_SUFFIXES:
            raise OutputError(
                f"video {path}: suffix {path.suffix or '(none)'!r} is not one of "
                f"{', '.join(VIDEO_SUFFIXES)} (H.264 containers ffmpeg writes)"
            )
        if out_dir is not None and path.is_relative_to(out_dir.path):
            if path == out_dir.path:
                raise OutputError(f"video {path} is the output directory itself")
            relative = path.relative_to(out_dir.path)
            if relative.parts[0] in reserved_names or relative.parts[0] == MANIFEST:
                raise OutputError(
                    f"video {path} would overwrite the run's own {relative.parts[0]}; choose another name"
                )
            _check_lengths(self.what, out_dir.path, len(os.fsencode(str(relative))))
            self.relative = relative
            return
        _check_lengths(self.what, path, len(STAGING_MARKER))
        if os.path.islink(path):
            raise OutputError(f"video {path} is a symbolic link; give the file itself")
        if path.is_dir():
            raise OutputError(f"video {path} is a directory")
        if os.path.lexists(path):
            if not path.is_file():
                raise OutputError(f"video {path} exists and is not a regular file")
            if not is_planbench_video(path):
                raise OutputError(
                    f"video {path} exists and planbench did not write it; choose another {option} or remove it yourself"
                )
        _probe(self.what, path)

    @property
    def is_reserved(self) -> bool:
        return self.relative is not None or self._lock_fd is not None

    @contextlib.contextmanager
    def reserved(self):
        """As ``_Target.reserved``; a video inside the output directory is covered by the
        directory's own reservation."""
        if self.relative is not None:
            yield self
            return
        with super().reserved():
            yield self

    @contextlib.contextmanager
    def staging(self):
        """Yield the path to render to; ``commit`` moves it to ``self.path`` afterwards."""
        tmp = _new_staging(self.path.parent, self.path.name)
        try:
            yield tmp / ("video" + self.path.suffix)
        except BaseException:
            with signals_deferred():
                shutil.rmtree(tmp, ignore_errors=True)
            raise
        self._staged = tmp

    def commit(self) -> None:
        if self._staged is None:
            return
        with signals_deferred():
            rendered = self._staged / ("video" + self.path.suffix)
            _usual_mode(rendered, 0o666)
            # Checked again: a file of someone else's may have appeared there during the run.
            taken = os.path.lexists(self.path) and (
                os.path.islink(self.path) or not self.path.is_file() or not is_planbench_video(self.path)
            )
            if taken:
                stamp = time.strftime("%Y%m%dT%H%M%SZ", time.gmtime())
                kept = self.path.with_name(f"{self.path.stem}.new-{stamp}{self.path.suffix}")
                os.rename(rendered, kept)
            else:
                os.replace(rendered, self.path)
            shutil.rmtree(self._staged, ignore_errors=True)
            self._staged = None
        if taken:
            raise OutputError(
                f"video {self.path} appeared during the run and planbench did not "
                f"write it; it was left as it is and this run's video is {kept}"
            )

    def discard(self) -> None:
        if self._staged is not None:
            with signals_deferred():
                shutil.rmtree(self._staged, ignore_errors=True)
            self._staged = None


def is_planbench_video(path: Path) -> bool:
    """Whether ``path`` is a video whose container carries planbench's ``comment`` tag."""
    import imageio_ffmpeg

    try:
        proc = subprocess.run(
            [imageio_ffmpeg.get_ffmpeg_exe(), "-hide_banner", "-nostdin", "-i", str(path)],
            capture_output=True,
            timeout=30,
        )
    except (OSError, subprocess.TimeoutExpired):
        return False
    text = proc.stderr.decode(errors="replace")
    return re.search(r"^\s*comment\s*:\s*" + re.escape(VIDEO_TAG), text, re.MULTILINE | re.IGNORECASE) is not None


def software_versions() -> dict:
    """The versions a run's numbers depend on: planbench, Python, mujoco, numpy, scipy."""
    import importlib.metadata
    import platform

    import mujoco
    import scipy

    try:
        planbench = importlib.metadata.version("planbench")
    except importlib.metadata.PackageNotFoundError:
        planbench = "not installed"
    return {
        "planbench": planbench,
        "python": platform.python_version(),
        "mujoco": mujoco.__version__,
        "numpy": np.__version__,
        "scipy": scipy.__version__,
    }


def read_log(path):
    """A run's log (``DIR/log.arrow`` or DIR): ``planbench.logfile.read_log``."""
    from planbench.logfile import read_log as read

    return read(path)


def summary_dict(result) -> dict:
    return {
        "scenario": result.scenario,
        "passed": result.passed,
        "seed": result.seed,
        "parameters": getattr(result, "parameters", None),
        "plant": getattr(result, "plant", None),
        "versions": software_versions(),
        "sim_time_s": result.sim_time_s,
        "wall_time_s": round(result.wall_time_s, 4),
        "realtime_factor": round(result.sim_time_s / result.wall_time_s, 3) if result.wall_time_s > 0 else None,
        "components": result.components,
        "plugins": result.plugins,
        "sensors": result.sensors,
        "checks": [c.to_json() for c in result.checks],
        "metrics": result.metrics,
    }


def _as_output_dir(out_dir, kind: str) -> OutputDir:
    return out_dir if isinstance(out_dir, OutputDir) else OutputDir(out_dir, kind=kind)


def save_timeseries(path, arrays: dict) -> None:
    """``np.savez_compressed(path, **arrays)``, where an array may also be one read from a log
    a chunk at a time (a ``logfile.LoggedSeries``: ``shape``, ``dtype`` and ``parts()``), whose
    rows are written as they are read (a long run's arrays are never whole in memory)."""
    from numpy.lib import format as npy

    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED, allowZip64=True) as archive:
        for name, value in arrays.items():
            with archive.open(f"{name}.npy", "w", force_zip64=True) as member:
                if hasattr(value, "parts"):  # (a logfile.LoggedSeries, read a chunk at a time)
                    npy.write_array_header_1_0(
                        member,
                        {"descr": npy.dtype_to_descr(value.dtype), "fortran_order": False, "shape": value.shape},
                    )
                    for part in value.parts():
                        member.write(part.tobytes())
                else:
                    npy.write_array(member, np.asanyarray(value), allow_pickle=True)


def write_run(
    result,
    setup,
    out_dir,
    video=None,
    camera: str = "overview",
    quiet: bool = True,
    more_videos: tuple = (),
    staging: Path | None = None,
) -> dict:
    """Write summary.json, timeseries.npz, report.png (and the video) of ``result``.

    ``staging``: the staging directory of ``out_dir`` the caller holds (``planbench.pipeline``
    opens it before the run, whose log streams into it: ``log.arrow``); the caller's
    ``out_dir.staging()`` swaps it in. None: a staging directory is made and swapped in here,
    and the log, streamed elsewhere, is copied into it a chunk at a time.

    ``out_dir``: an OutputDir (validated and reserved by the caller before simulating, as
    the CLI does) or a path, validated here. ``video``: a VideoFile or a path. A video inside
    ``out_dir`` is rendered into its staging directory; one outside into a staging directory
    of its own; both are moved into place only when everything is written.
    ``more_videos``: (file name, camera) pairs of further videos inside ``out_dir`` (the
    demo's close-ups). Returns the summary.
    """
    from planbench.logfile import LoggedSeries
    from planbench.render import render_video

    target = _as_output_dir(out_dir, "run")
    if video is not None and not isinstance(video, VideoFile):
        video = VideoFile(video, target)
    with contextlib.ExitStack() as stack:
        if not target.is_reserved:
            stack.enter_context(target.reserved())
        if video is not None and not video.is_reserved:
            stack.enter_context(video.reserved())
        try:
            held = (
                contextlib.nullcontext(staging)
                if staging is not None
                else target.staging({"scenario": result.scenario})
            )
            with held as tmp:
                summary = summary_dict(result)
                log_file = getattr(result.log, "file", None)
                if log_file is not None and not (tmp / "log.arrow").exists():
                    log_file.copy_to(tmp / "log.arrow")  # streamed elsewhere (a run not staged here)
                if log_file is not None:
                    summary["log"] = {
                        "path": "log.arrow",
                        "ticks": log_file.n,
                        "complete": log_file.complete,
                        "chunks": log_file.num_chunks,
                    }
                log = result.log
                stride = setup.output.output_stride
                names = ("t", "qpos", "qvel", "ctrl", "act", "actuator_force", "sensordata")
                if hasattr(log, "every"):  # from the log file (save_timeseries copies a chunk at a time)
                    arrays = {
                        name: log.every(name, stride)
                        if log.file is None or log.held(name)
                        else LoggedSeries(log.file, name, stride=stride)
                        for name in names
                    }
                    t_every = log.every("t", stride)
                else:
                    arrays = {name: getattr(log, name)[::stride] for name in names}
                    t_every = arrays["t"]
                n = log.n if hasattr(log, "every") else log.t.size
                # (an evaluation may return its series at every tick, strided here, or already
                # at every stride-th tick)
                series = setup.task.evaluation.timeseries(log)
                if stride > 1:  # every stride-th tick of the per-tick arrays
                    series = {k: v[::stride] if np.ndim(v) and np.shape(v)[0] == n else v for k, v in series.items()}
                    summary["timeseries_every_s"] = float(t_every[1] - t_every[0]) if n > stride else None
                arrays.update(series)
                save_timeseries(tmp / "timeseries.npz", arrays)
                setup.task.evaluation.report(log, result.checks, tmp / "report.png")
                render = dict(speed=setup.output.video_speed, quiet=quiet, frame_qpos=setup.output.video_qpos)
                if video is not None:
                    if video.relative is not None:
                        path = tmp / video.relative
                        path.parent.mkdir(parents=True, exist_ok=True)
                        frames = render_video(setup.physics.model.ptr, log, path, camera=camera, **render)
                    else:
                        with video.staging() as path:
                            frames = render_video(setup.physics.model.ptr, log, path, camera=camera, **render)
                    summary["video"] = {"path": str(video.path), "frames": frames, "camera": camera}
                    if setup.output.video_note:
                        summary["video"]["shows"] = setup.output.video_note
                for name, extra_camera in more_videos:
                    frames = render_video(setup.physics.model.ptr, log, tmp / name, camera=extra_camera, **render)
                    summary.setdefault("more_videos", []).append(
                        {"path": str(target.path / name), "frames": frames, "camera": extra_camera}
                    )
                (tmp / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
        except BaseException:
            if video is not None:
                video.discard()
            raise
        if video is not None:
            video.commit()
    return summary
