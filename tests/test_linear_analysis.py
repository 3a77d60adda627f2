"""The Nomoto reading of a linearised ship (steerlab.ships.linear_analysis.nomoto_from_linear)
is python-control's, bit for bit, without importing python-control."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from steerlab.ships.linear_analysis import _nomoto_from_linear_by_python_control, nomoto_from_linear
from steerlab.ships.registry import SHIPS


def _cases():
    """``(label, linear)``: a catalogue ship at a speed (``linear`` = ``(name, speed)``, linearised
    in the test, not at collection: some ships solve for their equilibrium first) or a random
    sway-yaw pair (``linear`` = ``(A, b)``)."""
    rng = np.random.default_rng(5)
    for name in sorted(SHIPS):
        if SHIPS[name].linearise is None:
            continue
        for speed in (1.0, 4.0, 8.0):
            yield f"{name}@{speed}", (name, speed)
    for k in range(40):                  # stable, unstable, fast and slow sway-yaw pairs
        A = rng.normal(size=(2, 2)) * 10.0 ** rng.uniform(-3, 0, size=(2, 2))
        yield f"random{k}", (A, rng.normal(size=2) * 10.0 ** rng.uniform(-4, -1))


@pytest.mark.parametrize("label,linear", list(_cases()), ids=lambda v: v if isinstance(v, str) else "")
def test_the_same_bits_as_python_control(label, linear, control):
    if isinstance(linear[0], str):
        linear = SHIPS[linear[0]].linearise(linear[1])
    ours = nomoto_from_linear(*linear)
    assert ours == _nomoto_from_linear_by_python_control(*linear), label


def test_the_esso_at_16_kn_reads_as_course_unstable():
    # the Esso tanker is course unstable at 16 kn (8.2 m/s): a pole in the right half-plane, and a
    # negative K and T in the first-order reading (linear_analysis module docstring)
    n = nomoto_from_linear(*SHIPS["esso"].linearise(8.2))
    assert n["K"] < 0 and n["T"] < 0 and min(n["T1"], n["T2"]) < 0 < n["T3"]


def test_designing_a_wave_filtered_law_imports_no_python_control():
    code = ("import sys, steerlab as sl\n"
            "sl.controller('pid+wf', ship='esso', speed_kn=16.0).reset().step(0.0, 0.0, 0.0, 0.1)\n"
            "print(sorted(m for m in ('control', 'scipy.signal') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip().splitlines()[-1] == "[]"
