"""A signal during ncd.io.netcdf.write_dataset leaves neither a partial file nor a hung process.

Policy (ncd/io/netcdf.py): SIGTERM/SIGINT remove the ``.<name>.<pid>.part`` file and end the
process with that signal; SIGKILL leaves it, and the next write of the same target
removes it.
"""
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
import xarray as xr

from ncd.io.netcdf import write_dataset

WRITER = """
import sys, numpy as np, xarray as xr
from ncd.io.netcdf import write_dataset
rng = np.random.default_rng(0)
ds = xr.Dataset({"impulse_n": (("run", "contact"), rng.random((4000, 6000)))})
print("ready", flush=True)
write_dataset(ds, sys.argv[1])
print("written", flush=True)
"""


def start_writer(target):
    proc = subprocess.Popen([sys.executable, "-c", WRITER, str(target)], stdout=subprocess.PIPE, text=True)
    assert proc.stdout.readline().strip() == "ready"
    deadline = time.monotonic() + 60
    while not list(target.parent.glob(f".{target.name}.*.part")):
        assert proc.poll() is None, "the writer ended before writing"
        assert time.monotonic() < deadline, "no .part file appeared"
        time.sleep(0.01)
    time.sleep(0.2)  # inside netCDF4/HDF5 now
    return proc


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
def test_signal_during_write_removes_the_part_file_and_ends(tmp_path, sig):
    target = tmp_path / "big.nc"
    proc = start_writer(target)
    proc.send_signal(sig)
    try:
        rc = proc.wait(timeout=30)
    except subprocess.TimeoutExpired:
        proc.kill()
        pytest.fail(f"writer hung after {sig.name}")
    assert rc == -sig, f"exit status {rc}, expected death by {sig.name}"
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_sigkill_leaves_a_part_that_the_next_write_removes(tmp_path):
    target = tmp_path / "big.nc"
    proc = start_writer(target)
    proc.kill()
    assert proc.wait(timeout=30) == -signal.SIGKILL
    stale = list(tmp_path.glob(".big.nc.*.part"))
    assert len(stale) == 1 and not target.exists()
    write_dataset(xr.Dataset({"impulse_n": ("run", np.arange(3.0))}), target)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["big.nc"]
    assert xr.load_dataset(target).impulse_n.attrs["units"] == "N s"


def test_a_live_writers_part_is_not_swept(tmp_path):
    target = tmp_path / "x.nc"
    live = tmp_path / f".x.nc.{os.getppid()}.part"  # the parent process exists
    live.write_bytes(b"")
    write_dataset(xr.Dataset({"impulse_n": ("run", np.arange(3.0))}), target)
    assert live.exists() and target.exists()
