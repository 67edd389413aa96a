"""Atomic file writing: a reader (or a crash half-way through rendering) never sees a partial file.

Every output is written first to a temporary file in the target's folder,
then moved over the target with os.replace.
"""
import argparse
import contextlib
import os
import pathlib
import tempfile


def _current_umask():
    mask = os.umask(0)
    os.umask(mask)
    return mask


_UMASK = _current_umask()


@contextlib.contextmanager
def atomic_path(target):
    """Yield a temporary path next to `target`; on success move it onto `target`, on error delete it.

    The temporary name keeps the target's extension (writers such as Pillow
    choose the format from it) and starts with a dot.
    """
    target = pathlib.Path(target)
    fd, tmp = tempfile.mkstemp(dir=target.parent, prefix=f".{target.stem}.", suffix=f".tmp{target.suffix}")
    os.close(fd)
    try:
        yield pathlib.Path(tmp)
        os.chmod(tmp, 0o666 & ~_UMASK)       # mkstemp makes 0600; give the file the usual permissions
        os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def write_text(target, text):
    """Writes `text` (UTF-8) to `target` atomically: readers see the old file or the whole new one."""
    with atomic_path(target) as tmp:
        tmp.write_text(text, encoding="utf-8")


def output_file(value):
    """An argparse `type` for a file a command will write: its folder must exist and be a writable
    folder, checked before the command computes anything (exit status 2, naming the path)."""
    path = pathlib.Path(value)
    folder = path.parent
    if path.is_dir():
        raise argparse.ArgumentTypeError(f"{value}: is a folder, expected a file name")
    if not folder.is_dir():
        raise argparse.ArgumentTypeError(f"{value}: the folder {folder} does not exist")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise argparse.ArgumentTypeError(f"{value}: the folder {folder} is not writable")
    return path


def write_new_file(folder, stem, suffix, text):
    """Writes `text` to `<stem><suffix>` in `folder` (created if missing) without ever replacing a
    file: when that name is taken, `<stem>-2<suffix>`, `-3`, ...  Written to a temporary file
    first, then linked under its name (os.link fails rather than replace).  Returns the path
    written.  For results that are all kept, one file a run."""
    folder = pathlib.Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    tmp = folder / f".{stem}{suffix}.tmp"
    tmp.write_text(text, encoding="utf-8")
    try:
        for n in range(1, 1000):
            path = folder / (f"{stem}{suffix}" if n == 1 else f"{stem}-{n}{suffix}")
            try:
                os.link(tmp, path)
                return path
            except FileExistsError:
                continue
        raise FileExistsError(f"{folder}: 999 files for {stem}")
    finally:
        tmp.unlink()
