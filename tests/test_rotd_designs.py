"""Record designs in the RotD measures of a pair (pga_rotd50, sa_rotd50, ...).

Oracles: pyrotd (the peer library of rotated spectra) for the stored per-record measures;
plain ``im = "pga"`` IDAs of the oriented records through the Python design function, whose
capacities times RotD50 / PGA of the record the object feels are the capacities in
pga_rotd50 (every measure here is linear in the record); Cornell's closed form for the rate
of a lognormal fragility under a power-law hazard.
"""

import math

import numpy as np
import pandas as pd
import pyrotd
import pytest
from _helpers import RECORD_STUDY_HEAD, write_ground_pairs

from rockstudy.constants import STANDARD_GRAVITY
from rockstudy.motions import Record
from rockstudy.study import StudyError, load_study, run_study
from rockstudy.study.analysis.record_fragility import ida_fragility
from rockstudy.study.analysis.risk import object_risk
from rockstudy.study.designs import records as rd
from rockstudy.study.report.sampled import make_report
from rockstudy.study.running.store import open_result

H2 = 'h2 = { match = "_X\\\\.AT2$", replace = "_Y.AT2" }'
SHEAR = "building = { uniform_shear = { n_storeys = 3, period = 0.3, damping = 0.05 } }"
#: pyrotd's angles: 0 to 179 degrees.
ANGLES = np.arange(180)
IDA = 'kind = "ida"\nstep = 0.05\ntolerance = 0.02'


@pytest.fixture(scope="module")
def pairs(tmp_path_factory):
    """Two records of two components, p{i}_X.AT2 and p{i}_Y.AT2 (the y one of another
    pulse, the stronger)."""
    folder = tmp_path_factory.mktemp("rotd_pairs")
    return write_ground_pairs(folder, 2, x=(0.7, 0.3, 2.5, 60), y=(0.9, 0.2, 4.0, 70), duration=4.0)


def pair_of(folder, i):
    """Record i as the study reads it: both components from its files."""
    x, y = (Record.from_at2(folder / f"p{i}_{c}.AT2") for c in "XY")
    return Record(x.acceleration, time=x.time, acceleration_y=y.acceleration, name=f"p{i}_X")


def padded(pair):
    """The pair followed by 60 s of rest: pyrotd's oscillator is a periodic (FFT) one, which
    equals the oscillator started at rest once the response has died out before the record
    repeats (at T = 0.5 s and 5 %, e^(-0.05 (2 pi / 0.5) 60) = 4e-17)."""
    rest = np.zeros(int(round(60.0 / pair.dt)))
    return Record(
        np.r_[pair.acceleration, rest], dt=pair.dt, acceleration_y=np.r_[pair.acceleration_y, rest]
    )


def pyrotd_sa(pair, period, percentile):
    """pyrotd's RotD pseudo-spectral acceleration, its oscillator upsampled 4 times."""
    long = padded(pair)
    out = pyrotd.calc_rotated_spec_accels(
        long.dt,
        long.acceleration,
        long.acceleration_y,
        [1.0 / period],
        0.05,
        percentiles=[percentile],
        angles=ANGLES,
        max_freq_ratio=4 * (0.5 / long.dt) * period,
    )
    return float(out.spec_accel[0])


def pyrotd_pga(pair, percentile):
    out = pyrotd.calc_rotated_percentiles(
        [pair.acceleration, pair.acceleration_y], ANGLES, [percentile], method="rigorous"
    )
    return float(out.spec_accel[0])


def study_file(folder, where, motion, design, extra="", name="rotd.toml"):
    text = RECORD_STUDY_HEAD.replace("n = 3", "n = 2") + (
        f'[motion]\nkind = "record"\nfiles = "{folder}"\n{motion}\n[design]\n{design}\n'
        '[run]\noutputs = ["max_rotation", "overturned"]\n' + extra
    )
    path = where / name
    path.write_text(text)
    return load_study(path)


def hazard(im, period=None):
    at = "" if period is None else f"period = {period}\n"
    return f'[hazard]\nkind = "power_law"\nim = "{im}"\n{at}k0 = 1e-4\nk = 2.5\nunits = "g"\n'


def run(study, where, name, client):
    out = where / f"{name}.zarr"
    result = run_study(study, out, client=client, base_dir=where, progress=False)
    assert result.failed_samples == 0
    return out


def cornell(theta, beta, k0=1e-4, k=2.5):
    """lambda = k0 theta^-k exp(k^2 beta^2 / 2) of a lognormal fragility (theta in g)."""
    return k0 * theta**-k * math.exp(0.5 * (k * beta) ** 2)


def test_an_ida_over_orientations_in_pga_rotd50_runs_reports_and_integrates(
    pairs, client, tmp_path
):
    design = f'{IDA}\nim = "pga_rotd50"\norientations = 2'
    study = study_file(pairs, tmp_path, H2, design, hazard("pga_rotd50"))
    out = run(study, tmp_path, "ida", client)
    cube = open_result(out).load()
    for i in range(2):
        pair = pair_of(pairs, i)
        got = float(cube["pga_rotd50"].isel(record=i))
        assert got == pytest.approx(pyrotd_pga(pair, 50), rel=1e-3)
    # the same records, oriented, in a plain PGA IDA of the Python design function
    angles = cube["orientation"].values
    blocks = {
        "half_diagonal": cube["half_diagonal"].values,
        "slenderness": cube["slenderness"].values,
    }
    for i in range(2):
        pair = pair_of(pairs, i)
        for o, psi in enumerate(angles):
            felt = pair.oriented(float(psi))
            plain = rd.incremental_dynamic_analysis(
                [felt], blocks, im="pga", step=0.05, tolerance=0.02
            )
            want = plain["capacity"].values[0] * pyrotd_pga(pair, 50) / felt.peak
            got = cube["capacity"].isel(record=i, orientation=o).values
            np.testing.assert_allclose(got, want, rtol=1e-3)
    make_report(out, tmp_path / "report")
    page = (tmp_path / "report" / "design_worst" / "index.html").read_text()
    assert "PGA_ROTD50 hazard curve" in page and "Annual rate of overturning" in page
    curve = study.hazard.curve()
    worst = cube.isel(orientation=0)
    rates = object_risk(worst, curve, n_boot=0)
    fit = ida_fragility(worst, "pga_rotd50", by="structure", n_boot=0)
    fitted = 0
    for name in worst["structure"].values:
        theta, beta = (float(fit.loc[name, k]) for k in ("theta", "beta"))
        if np.isfinite(theta) and np.isfinite(beta):
            rate = float(rates["annual_rate"].sel(structure=name))
            assert rate == pytest.approx(cornell(theta, beta), rel=1e-6)
            fitted += 1
    assert fitted


def test_stripes_on_a_floor_in_sa_rotd50_scale_the_ground_pair(pairs, client, tmp_path):
    period, levels = 0.5, [0.3, 0.6]  # g
    scale_to = f'scale_to = {{ im = "sa_rotd50", period = {period}, units = "g", value = '
    motion = f'{H2}\n{SHEAR}\nfloor = 2\n{scale_to}{{ dist = "grid", values = {levels} }} }}'
    study = study_file(pairs, tmp_path, motion, 'kind = "stripes"', hazard("sa_rotd50", period))
    out = run(study, tmp_path, "stripes", client)
    cube = open_result(out).load()
    for i in range(2):
        want = pyrotd_sa(pair_of(pairs, i), period, 50)
        got = float(cube["sa_rotd50"].isel(record=i).sel(period=period))
        assert got == pytest.approx(want, rel=1e-3)
        scale = cube["scale"].isel(record=i).transpose("structure", "level").values
        target = np.array(levels) * STANDARD_GRAVITY / want
        np.testing.assert_allclose(scale, np.broadcast_to(target, scale.shape), rtol=1e-3)
    make_report(out, tmp_path / "report")
    page = (tmp_path / "report" / "index.html").read_text()
    assert "SA_ROTD50 at T = 0.5 s hazard curve" in page


def test_a_cloud_with_a_rotd100_hazard_stores_the_pairs_rotd100(pairs, client, tmp_path):
    study = study_file(pairs, tmp_path, H2, 'kind = "cloud"', hazard("pga_rotd100"))
    out = run(study, tmp_path, "cloud", client)
    cube = open_result(out).load()
    for i in range(2):
        got = float(cube["pga_rotd100"].isel(record=i))
        assert got == pytest.approx(pyrotd_pga(pair_of(pairs, i), 100), rel=1e-3)
    make_report(out, tmp_path / "report")
    assert "PGA_ROTD100 hazard curve" in (tmp_path / "report" / "index.html").read_text()
    table = pd.read_csv(tmp_path / "report" / "records.csv", index_col=0)
    want = cube["pga_rotd100"].values / STANDARD_GRAVITY
    np.testing.assert_allclose(table["PGA RotD100 [g]"].values, want, rtol=1e-9)


@pytest.mark.parametrize(
    ("design", "extra", "field"),
    [
        (f'{IDA}\nim = "pga_rotd50"', "", "design.im"),
        ('kind = "cloud"', hazard("sa_rotd50", 0.5), "hazard.im"),
    ],
)
def test_a_pair_measure_on_records_of_one_component_is_refused_by_field(
    pairs, tmp_path, design, extra, field
):
    if "sa_rotd50" in extra:
        design += "\nperiods = [0.5]"
    with pytest.raises(StudyError, match=rf"{field}: .* measure of two horizontal components"):
        study_file(pairs, tmp_path, "", design, extra)


def test_stripes_scaled_to_a_pair_measure_need_two_components(pairs, tmp_path):
    motion = 'scale_to = { im = "pga_rotd50", value = { dist = "grid", values = [1.0] } }'
    with pytest.raises(StudyError, match=r"motion.scale_to.im: 'pga_rotd50' is a measure of two"):
        study_file(pairs, tmp_path, motion, 'kind = "stripes"')


def test_monte_carlo_rows_on_a_floor_scale_the_ground_pair_to_its_rotd50(pairs, tmp_path):
    from _helpers import run_rows

    text = RECORD_STUDY_HEAD.replace('kind = "lhs"\nn = 3', 'kind = "monte_carlo"\nn = 4') + (
        f'[motion]\nkind = "record"\nfiles = "{pairs}"\n{H2}\n{SHEAR}\nfloor = 3\n'
        'scale_to = { im = "pga_rotd50", units = "g", value = 0.4 }\n'
        '[run]\noutputs = ["max_rotation", "overturned"]\n'
    )
    (tmp_path / "rows.toml").write_text(text)
    study = load_study(tmp_path / "rows.toml")
    design, out = run_rows(study, tmp_path)
    for i, r in enumerate(design["record"].values):
        pair = pair_of(pairs, int(r))
        want = 0.4 * STANDARD_GRAVITY / pyrotd_pga(pair, 50)
        assert out["scale"][i] == pytest.approx(want, rel=1e-3)
        assert out["pga"][i] == pytest.approx(pair.peak * want, rel=1e-3)  # the ground's
