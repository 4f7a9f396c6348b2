"""Shared by the validation scripts (surface_models.py, volume_table.py): CAD file extensions and a
subprocess runner with a time bound."""
import os
import subprocess
import time

CAD_EXT = {".stp", ".step", ".igs", ".iges", ".brep", ".rle"}


def run(cmd, timeout, env=None):
    """(exit code or 'timeout', stdout, stderr, seconds)."""
    t0 = time.monotonic()
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout,
                           env={**os.environ, **(env or {})})
        return p.returncode, p.stdout, p.stderr, time.monotonic() - t0
    except subprocess.TimeoutExpired:
        return "timeout", "", "", time.monotonic() - t0
