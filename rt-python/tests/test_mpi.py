"""`composite_mpi` over real MPI processes (mpirun + mpi4py)."""

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

SCRIPT = Path(__file__).with_name("mpi_composite.py")

mpirun = shutil.which("mpirun")
try:
    import mpi4py  # noqa: F401
except ImportError:
    mpi4py = None

needs_mpi = pytest.mark.skipif(mpirun is None or mpi4py is None, reason="needs mpirun and mpi4py")


def run(n, mode):
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    return subprocess.run([mpirun, "--oversubscribe", "-np", str(n), sys.executable, str(SCRIPT), mode],
                          capture_output=True, text=True, timeout=120, env=env)


@needs_mpi
@pytest.mark.parametrize("n", [1, 2, 3, 4])
def test_ranks_composite_to_the_whole_scene_bit_for_bit(n):
    r = run(n, "compose")
    assert r.returncode == 0, r.stdout + r.stderr
    assert f"OK {n} ranks" in r.stdout


@needs_mpi
def test_a_silent_rank_is_an_error_on_the_others_not_a_hang():
    r = run(3, "silent")
    assert r.returncode == 0, r.stdout + r.stderr
    for rank in (0, 2):
        assert f"rank {rank}: ValueError: compositing failed" in r.stdout, r.stdout + r.stderr


PIECES = Path(__file__).with_name("mpi_pieces.py")


@needs_mpi
@pytest.mark.parametrize("n", [1, 2, 3, 4])
@pytest.mark.parametrize("cutoff", ["knife", "interferometry", "bos", "focusing"])
def test_pieces_give_the_whole_grids_image_bit_for_bit(n, cutoff):
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    r = subprocess.run([mpirun, "--oversubscribe", "-np", str(n), sys.executable, str(PIECES), cutoff],
                       capture_output=True, text=True, timeout=300, env=env)
    assert r.returncode == 0, r.stdout + r.stderr
    assert f"{cutoff}: {n} ranks OK" in r.stdout, r.stdout + r.stderr


@needs_mpi
def test_bad_input_to_the_pieces_raises_clear_exceptions():
    r = subprocess.run([sys.executable, str(Path(__file__).with_name("mpi_bad_pieces.py"))],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "bad pieces: 9 cases raise" in r.stdout


@needs_mpi
@pytest.mark.parametrize("how", ["0", "1", "callback"])
def test_ctrl_c_on_one_rank_stops_every_rank(how):
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    script = Path(__file__).with_name("mpi_interrupt.py")
    r = subprocess.run([mpirun, "--oversubscribe", "-np", "2", sys.executable, str(script), how],
                       capture_output=True, text=True, timeout=300, env=env)
    assert r.returncode == 0, r.stdout + r.stderr
    lines = re.findall(r"rank (\d): (.*) after ([\d.]+) s", r.stdout)
    said = {int(k): (what, float(t)) for k, what, t in lines}
    stopped = 0 if how == "callback" else int(how)
    assert set(said) == {0, 1}, r.stdout + r.stderr
    what, took = said[stopped]
    assert what == ("Enough" if how == "callback" else "KeyboardInterrupt"), r.stdout
    other, heard = said[1 - stopped]
    assert other == f"ValueError: rank {1 - stopped}: rank {stopped} failed", r.stdout
    # Uninterrupted, the render takes about ten seconds; SIGINT comes at
    # 2 s, a poll (50 ms) and a photon's leg end it there; the peer hears
    # within a round of the trade, long before the 60 s timeout.
    if how != "callback":
        assert took < 2.0 + 3.0, r.stdout
    assert heard < took + 10.0, r.stdout
