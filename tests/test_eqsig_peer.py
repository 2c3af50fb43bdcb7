"""Intensity measures against a peer library, eqsig (Millen), on the shared real records.

Where the definitions agree the measures agree to 2e-3 or better; each remaining difference is
a stated convention (docs/records.rst):

- PGV: eqsig integrates the raw record (no baseline); ours removes the constant that ends the
  ground at rest. eqsig on our offset-corrected acceleration is the oracle (same trapezoid).
- D5-95: eqsig reports the sample times just inside 5 % and 95 % of its (same) Husid curve;
  ours interpolates between samples, so ours - eqsig lies in [0, 2 dt].
- Sa: eqsig takes the peak at the samples only (and PGA below 6 dt); ours includes the peaks
  between samples and in the free vibration after the record. On the raw samples eqsig <=
  ours (3.8 % below at 10 dt on Gazli); on the record linearly resampled 16 times finer (the
  same piecewise-linear record), within 2e-3 (measured: 1e-5).
"""

import numpy as np
import pytest

eqsig = pytest.importorskip("eqsig")

from rockstudy.motions import Record  # noqa: E402
from rockstudy.motions.intensity import baseline_offset  # noqa: E402


def _records(records_dir):
    recs = [Record.from_at2(p) for p in sorted(records_dir.glob("*.AT2"))]
    return recs + [Record.from_csv(records_dir / "elcentro_NS.dat")]


def test_pga_pgv_arias_cav_duration_against_eqsig(records_dir):
    for rec in _records(records_dir):
        a, dt = np.array(rec.acceleration), rec.dt
        sig = eqsig.AccSignal(a, dt)
        im = rec.intensity_measures()
        assert im["pga"] == pytest.approx(np.max(np.abs(sig.values)), rel=1e-12)
        assert im["arias"] == pytest.approx(eqsig.im.calc_arias_intensity(sig)[-1], rel=2e-3)
        assert im["cav"] == pytest.approx(eqsig.im.calc_cav(sig)[-1], rel=2e-3)
        corrected = eqsig.AccSignal(a - baseline_offset(rec.time, a), dt)
        assert im["pgv"] == pytest.approx(np.max(np.abs(corrected.velocity)), rel=2e-3)
        d595 = eqsig.im.calc_sig_dur(sig)
        assert 0.0 <= im["significant_duration"] - d595 <= 2 * dt + 1e-9


def test_sa_against_eqsig_for_periods_above_ten_dt(records_dir):
    for rec in _records(records_dir):
        a, dt = np.array(rec.acceleration), rec.dt
        periods = np.geomspace(10 * dt, 5.0, 12)
        sa = rec.intensity_measures(periods=periods)["sa"]
        _, _, raw = eqsig.sdof.pseudo_response_spectra(a, dt, periods, 0.05)
        assert np.all(raw <= sa * (1 + 1e-6))
        k = 16
        fine = np.interp(np.arange((a.size - 1) * k + 1) / k, np.arange(a.size), a)
        _, _, dense = eqsig.sdof.pseudo_response_spectra(fine, dt / k, periods, 0.05)
        np.testing.assert_allclose(sa, dense, rtol=2e-3)
