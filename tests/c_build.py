"""The C build that tests share: c/Makefile's targets with its default flags, in one BUILD directory
for the whole test run, across pytest-xdist's workers.

make is incremental, so the library and its sanitizer variant are compiled once per run instead of
once per test module and worker.  An exclusive lock on a file beside the directory serialises the
makes: two makes writing one BUILD at once would race on the same objects.  A test that builds with
other flags, plants an error or runs something long uses its own directory instead.
"""
import contextlib
import fcntl
import os
import shutil
import subprocess

from conftest import ROOT

C_DIR = ROOT / "c"
MAKE = shutil.which("make")


def shared_dir(tmp_path_factory):
    """The shared BUILD: under the run's common temporary root (the workers' parent) with xdist."""
    base = tmp_path_factory.getbasetemp()
    root = base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base
    return root / "shared-c-build"


@contextlib.contextmanager
def _locked(build):
    build.parent.mkdir(parents=True, exist_ok=True)
    with open(build.parent / "shared-c-build.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(lock, fcntl.LOCK_UN)


def make_shared(tmp_path_factory, *targets, env=None):
    """Runs `make TARGETS` in the shared BUILD (a target naming a file is given relative to BUILD, as
    '{build}/name'); returns (BUILD, the CompletedProcess)."""
    build = shared_dir(tmp_path_factory)
    targets = [t.format(build=build) for t in targets]
    with _locked(build):
        result = subprocess.run([MAKE, "-s", "-j2", f"BUILD={build}", "CFLAGS=-O2", *targets], cwd=C_DIR, capture_output=True,
                                text=True, env=env)
    return build, result
