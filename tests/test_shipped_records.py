"""The synthetic near-fault records shipped in data/records: regenerated bit for bit by the
script, read back through the PEER reader, with the stated pulse period recovered."""

from pathlib import Path

import numpy as np
import pytest

from rockstudy.constants import STANDARD_GRAVITY, G
from rockstudy.motions import Record, load_suite
from rockstudy.motions.shipped import (
    SHIPPED_DT,
    SHIPPED_SUITE,
    SHIPPED_VERTICAL_RULE,
    at2_text,
    shipped_suite_texts,
    write_shipped_suite,
)

DATA = Path(__file__).resolve().parents[1] / "data" / "records"


def test_shipped_files_equal_the_regenerated_ones(tmp_path):
    written = write_shipped_suite(tmp_path)
    shipped = sorted(p.name for p in DATA.glob("*.AT2"))
    assert shipped == sorted(p.name for p in written)
    assert len(shipped) == 2 * len(SHIPPED_SUITE)
    for path in written:
        assert (DATA / path.name).read_bytes() == path.read_bytes(), path.name
        assert path.stat().st_size < 64_000  # a few tens of KB each


def test_headers_say_synthetic_with_generator_seed_and_parameters():
    texts = shipped_suite_texts()
    for name, period, pga_g, seed in SHIPPED_SUITE:
        (h,) = [t for k, t in texts.items() if k.startswith(name) and k.endswith("_H.AT2")]
        title, call = h.splitlines()[:2]
        assert "SYNTHETIC" in title and "not a recording" in title
        assert "synthetic_near_fault" in call
        assert f"seed={seed}" in call and f"pulse_period={period!r}" in call
        assert f"pga={pga_g!r}*g" in call


@pytest.mark.parametrize("row", SHIPPED_SUITE, ids=[r[0] for r in SHIPPED_SUITE])
def test_read_back_with_the_stated_pulse_period(row):
    name, period, pga_g, _ = row
    (h,) = DATA.glob(f"{name}_*_H.AT2")
    v = h.with_name(h.name.replace("_H.AT2", "_UP.AT2"))
    rec = Record.from_at2(h, vertical=v)
    assert rec.dt == pytest.approx(SHIPPED_DT, rel=1e-12)
    # 8 significant figures in g: the stated PGA to 1e-7
    assert rec.peak / STANDARD_GRAVITY == pytest.approx(pga_g, rel=1e-7)
    assert rec.vertical is not None and 0 < np.max(np.abs(rec.vertical)) < G
    pulse = rec.pulse(method="mavroeidis")
    assert pulse.period == pytest.approx(period, rel=0.05)
    assert pulse.pulse_like


def test_the_folder_reads_as_a_suite_of_hv_pairs():
    recs = load_suite(DATA, vertical=SHIPPED_VERTICAL_RULE)
    assert [r.name.split("_")[0] for r in recs] == [row[0] for row in SHIPPED_SUITE]
    assert all(r.vertical is not None for r in recs)


def test_at2_text_round_trips_through_the_reader(tmp_path):
    values = np.array([0.0, 0.125, -0.5, 1.0e-6, 0.3, -0.2, 0.01])
    path = tmp_path / "x.AT2"
    path.write_text(at2_text(values, 0.02, "title", "made by a test"))
    rec = Record.from_at2(path)
    np.testing.assert_allclose(rec.acceleration / STANDARD_GRAVITY, values, rtol=1e-7, atol=0)
    assert rec.dt == 0.02
    with pytest.raises(ValueError, match="title"):
        at2_text(values, 0.02, "two\nlines", "x")
