"""The numba kernel of two stacked blocks (simulate_batch(structure=StackedBlocks)) against
independent oracles: the solve_ivp reference of the same model at rtol 1e-12 on random
scenes under pulses and generated records, and Housner's single-block batch in the limits
where the assembly is one block (a plinth that cannot move; an upper block of vanishing
mass)."""

import os
import warnings

import numpy as np
import pytest

from rockstudy.constants import G
from rockstudy.dynamics._stacked_batch import kernel_rows
from rockstudy.dynamics.batch import simulate_batch
from rockstudy.dynamics.stacked_reference import simulate_stacked
from rockstudy.dynamics.two_body_batch import OVERTURNED_BODY
from rockstudy.motions.pulses import CosinePulse, RickerWavelet, SinePulse
from rockstudy.motions.records import Record
from rockstudy.structures import Block, StackedBlocks

#: The kernel's rtol in the comparison with the reference (run at 1e-12).
KERNEL_RTOL = 1e-10
#: Error floor of a rotation, as a fraction of its block's alpha (the house's accuracy
#: measure, benchmarks/contact_accuracy.py): |kernel - reference| <= 10 rtol (|x| + FLOOR alpha).
FLOOR = 1e-2
#: The amplitude perturbation that tells a threshold-band scene: one whose reference answer
#: moves beyond the tolerance (or changes its decision) when the amplitude moves by it.
BAND = 1e-9


def _assembly(rng):
    """A random plinth and statue: the statue's base on the plinth's top, offset or not."""
    a1, r1 = rng.uniform(0.15, 0.35), rng.uniform(0.6, 2.0)
    a2 = rng.uniform(0.12, 0.3)
    b1 = r1 * np.sin(a1)
    r2 = min(rng.uniform(0.3, 1.2), 0.9 * b1 / np.sin(a2))
    b2 = r2 * np.sin(a2)
    e = rng.uniform(-0.5, 0.5) * (b1 - b2) if rng.random() < 0.3 else 0.0
    pair = StackedBlocks(Block(r1, a1), Block(r2, a2), rng.uniform(0.3, 3.0), offset=e)
    return pair, G * np.tan(min(a1, a2))


def _pulse(rng, ground):
    """A sine, cosine or Ricker pulse of 1.05-4 times the uplift acceleration."""
    cls = (SinePulse, CosinePulse, RickerWavelet)[rng.integers(3)]
    amp = ground * rng.uniform(1.05, 4.0) * rng.choice([-1.0, 1.0])
    per = rng.uniform(0.2, 1.5)
    return cls(amp, per) if cls is RickerWavelet else cls(amp, per, 1)


def _record(rng, ground):
    """A generated record: smoothed white noise under a sine envelope, 1-2 s at 0.02 s,
    peaking at 1-3 times the uplift acceleration."""
    n = int(rng.uniform(1.0, 2.0) / 0.02)
    t = np.arange(n) * 0.02
    acc = np.convolve(rng.normal(size=n), np.ones(5) / 5, "same") * np.sin(np.pi * t / t[-1])
    acc *= ground * rng.uniform(1.0, 3.0) / np.abs(acc).max()
    return Record(np.r_[acc, 0.0], dt=0.02)


def _scaled(motion, factor):
    """The motion with its amplitude times ``factor``."""
    if isinstance(motion, Record):
        return motion.scaled(factor)
    if isinstance(motion, RickerWavelet):
        return RickerWavelet(motion.amplitude * factor, motion.period)
    return type(motion)(motion.amplitude * factor, motion.period, motion.cycles)


def _reference(pair, motion, t_max):
    """(max rotations, overturned_body code, whether the reference missed an impact)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = simulate_stacked(pair, motion, rtol=1e-12, t_max=t_max)
    peaks = np.array([r.max_rotation_lower, r.max_rotation_upper])
    return peaks, OVERTURNED_BODY[r.overturned_body], r.info["missed_impacts"] > 0


def _agrees(peaks, body, ref_peaks, ref_body, alphas):
    scale = np.maximum(np.abs(peaks), np.abs(ref_peaks)) + FLOOR * alphas
    return body == ref_body and np.all(np.abs(peaks - ref_peaks) <= 10 * KERNEL_RTOL * scale)


def _compare(scenes, t_extra):
    """Count the scenes where the kernel agrees with the reference, those in the threshold
    band (or where the reference itself reports a missed impact) and the disagreements."""
    pairs, motions = zip(*scenes, strict=True)
    t_max = max(m.duration for m in motions) + t_extra
    cols = kernel_rows(list(pairs), list(motions), KERNEL_RTOL, 1_000_000, t_max=t_max)
    tally = {"agree": 0, "band": 0, "wrong": []}
    for i, (pair, motion) in enumerate(scenes):
        alphas = np.array([pair.lower.slenderness, pair.upper.slenderness])
        peaks = np.array([cols["max_rotation_lower"][i], cols["max_rotation_upper"][i]])
        ref_peaks, ref_body, missed = _reference(pair, motion, t_max)
        if not missed and _agrees(peaks, cols["overturned_body"][i], ref_peaks, ref_body, alphas):
            tally["agree"] += 1
            continue
        moved_peaks, moved_body, _ = _reference(pair, _scaled(motion, 1.0 + BAND), t_max)
        if missed or not _agrees(moved_peaks, moved_body, ref_peaks, ref_body, alphas):
            tally["band"] += 1
        else:
            tally["wrong"].append((i, peaks, ref_peaks, cols["overturned_body"][i], ref_body))
    return tally


#: Scenes per case; ROCKSTUDY_STACKED_SCENES raises it (the full accuracy run:
#: ``ROCKSTUDY_STACKED_SCENES=70 pytest tests/test_stacked_kernel.py``, 210 scenes).
SCENES = int(os.environ.get("ROCKSTUDY_STACKED_SCENES", "20"))

#: (kind of motion, seed, seconds of free rocking compared after the motion).
CASES = [("pulse", 0, 2.0), ("pulse", 1, 2.0), ("record", 7, 1.0)]


@pytest.mark.parametrize("kind, seed, t_extra", CASES)
def test_kernel_matches_the_reference_on_random_scenes(kind, seed, t_extra):
    """Max rotations within 10 rtol (over |x| + 1e-2 alpha) of the rtol 1e-12 reference and
    the same overturned body, on random assemblies under pulses and generated records,
    except in the threshold band (the reference's own answer moves when the amplitude
    moves by 1e-9; or it reports an impact its steps missed), which holds few scenes."""
    rng, n = np.random.default_rng(seed), SCENES
    make = _pulse if kind == "pulse" else _record
    scenes = []
    for _ in range(n):
        pair, ground = _assembly(rng)
        scenes.append((pair, make(rng, ground)))
    tally = _compare(scenes, t_extra)
    assert tally["wrong"] == []
    assert tally["band"] <= n // 4


def _record_for_limits():
    """A generated 3 s record (two decaying sines and a pulse), peaking near 3 m/s^2."""
    t = np.arange(0.0, 3.0, 0.01)
    acc = 2.0 * np.sin(2 * np.pi * t / 0.7) * np.exp(-0.6 * t) + 1.2 * np.sin(2 * np.pi * t / 0.3)
    return Record(np.r_[acc, 0.0], dt=0.01)


def test_plinth_that_cannot_move_leaves_the_statue_housners_block():
    """A wide, heavy plinth (alpha 0.9: it would need u_g'' > g tan 0.9) never lifts under a
    record: the statue is Housner's block of the single-block batch, max rotation to 1e-9."""
    record, scale = _record_for_limits(), np.array([0.6, 1.0, 1.4, 1.9, 2.5, -1.7])
    pair = StackedBlocks(Block(6.0, 0.9), Block(0.5, 0.2), density_ratio=0.5)
    got = simulate_batch(structure=pair, record=record, scale=scale, rtol=1e-10)
    ref = simulate_batch(half_diagonal=0.5, slenderness=0.2, record=record, scale=scale, rtol=1e-10)
    assert np.all(got["max_rotation_lower"] == 0.0) and np.all(got["status"] == 0)
    np.testing.assert_array_equal(got["overturned"], ref["overturned"])
    np.testing.assert_allclose(got["max_rotation_upper"], ref["max_rotation"], rtol=1e-9)
    assert 0 < ref["overturned"].sum() < len(scale)  # both outcomes are checked


def test_upper_block_of_vanishing_mass_leaves_the_plinth_housners_block():
    """A statue of density ratio 1e-9 loads the plinth with nothing: the plinth is Housner's
    block of the single-block batch, max rotation to 1e-7 (while the statue stays on)."""
    record, scale = _record_for_limits(), np.array([0.8, 1.0, 1.3, 1.6, -1.2])
    pair = StackedBlocks(Block(1.0, 0.25), Block(0.1, 0.5), density_ratio=1e-9)
    got = simulate_batch(structure=pair, record=record, scale=scale, rtol=1e-10)
    ref = simulate_batch(
        half_diagonal=1.0, slenderness=0.25, record=record, scale=scale, rtol=1e-10
    )
    assert np.all(got["overturned_body"] != OVERTURNED_BODY["upper"])
    assert np.sum(got["max_rotation_lower"] > 0.0) >= 3  # the plinth rocks in most rows
    np.testing.assert_array_equal(got["overturned"], ref["overturned"])
    np.testing.assert_allclose(got["max_rotation_lower"], ref["max_rotation"], rtol=1e-7)


def test_status_flags_rows_cut_by_max_steps():
    """A row whose phase needs more steps than max_steps has status 1; a row that never
    lifts (below g tan alpha of both interfaces) needs no steps and has status 0."""
    pair = StackedBlocks(Block(1.0, 0.3), Block(0.5, 0.2))
    amplitude = np.array([0.2, 6.0])
    out = simulate_batch(structure=pair, amplitude=amplitude, period=0.8, max_steps=3)
    np.testing.assert_array_equal(out["status"], [0, 1])
    full = simulate_batch(structure=pair, amplitude=amplitude, period=0.8)
    np.testing.assert_array_equal(full["status"], [0, 0])
