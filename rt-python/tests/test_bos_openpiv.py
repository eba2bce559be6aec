"""BOS closure against an outside tool: OpenPIV's cross-correlation of
rt's reference → flow pair (rtvis.bos and the `rt bos` command, with and
without sensor noise) against rt's ground truth averaged over each
interrogation window. The logic lives in examples/bos_openpiv.py, which
`rt-report bos` runs for its table."""

import sys
from pathlib import Path

import pytest

pytest.importorskip("openpiv")
pytest.importorskip("imageio")

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))
import bos_openpiv  # noqa: E402
from helpers import rt_binary  # noqa: E402


def test_openpiv_measures_rts_displacement_with_the_same_sign():
    rows = bos_openpiv.closure(rt_binary())
    assert len(rows) >= 2
    for r in rows:
        # A few pixels of displacement: a real signal for PIV.
        assert 1.0 < r["max_truth_px"] < 10.0, r
        # Same sign and shape (a sign error gives ≈ −1), sub-pixel agreement.
        assert r["correlation"] >= 0.98, r
        assert r["rms_px"] <= 0.1, r
