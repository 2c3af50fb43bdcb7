"""Every record design's Python result saves to netCDF and reads back equal.

Two writers: scipy's netCDF-3 (the engine xarray picks with only the package's own
dependencies installed) and h5netcdf (netCDF-4). The oracle is the dataset in memory:
``xarray.testing.assert_identical`` after the round trip, and the CF rules the files follow
(``flag_meanings`` a space-separated string of one word per value).
"""

import pytest
import xarray as xr

import rockstudy as rs
from rockstudy.motions import Record, synthetic_near_fault
from rockstudy.study.designs import records as rd

ENGINES = ("scipy", "h5netcdf")


@pytest.fixture(scope="module")
def suite():
    recs = [
        synthetic_near_fault(pulse_period=tp, pga=3.0, seed=3 + i, duration=4.0)
        for i, tp in enumerate((0.5, 0.9))
    ]
    return [Record(r.acceleration, dt=r.dt, name=f"nf{i}") for i, r in enumerate(recs)]


OBJECTS = {
    "bust": rs.Block.from_dimensions(width=0.3, height=0.9),
    "vase": rs.Block.from_dimensions(width=0.4, height=1.0),
}


def _designs(suite):
    yield "cloud", rd.cloud(suite, OBJECTS)
    yield "cloud with spectra", rd.cloud(suite, OBJECTS, periods=[0.3, 1.0])
    yield "stripes", rd.multiple_stripes(suite, OBJECTS, levels=[1.0, 2.0])
    yield "ida", rd.incremental_dynamic_analysis(suite, OBJECTS, max_pga_ratio=6.0)
    yield (
        "ida in sa",
        rd.incremental_dynamic_analysis(suite, OBJECTS, im="sa", period=0.5, max_pga_ratio=6.0),
    )


@pytest.fixture(scope="module")
def results(suite):
    return dict(_designs(suite))


@pytest.mark.parametrize("engine", ENGINES)
def test_every_design_round_trips_through_netcdf(results, engine, tmp_path):
    for name, ds in results.items():
        path = tmp_path / f"{name.replace(' ', '_')}.nc"
        ds.to_netcdf(path, engine=engine)
        with xr.open_dataset(path, engine=engine) as back:
            xr.testing.assert_identical(ds, back.load())


def test_the_record_coordinate_is_the_records_names(results, suite):
    for ds in results.values():
        assert list(ds["record"].values) == [r.name for r in suite]
        assert list(ds["record_name"].values) == [r.name for r in suite]
    ida = results["ida"]
    assert float(ida["capacity"].sel(record="nf1", structure="vase")) == float(
        ida["capacity"].isel(record=1, structure=1)
    )


def test_repeated_or_missing_names_give_distinct_labels(suite):
    twice = [suite[0], suite[0], suite[1]]
    ds = rd.cloud(twice, OBJECTS)
    labels = list(ds["record"].values)
    assert len(set(labels)) == 3
    assert labels[0] == "nf0" and labels[2] == "nf1"
    assert list(ds["record_name"].values) == ["nf0", "nf0", "nf1"]


def test_flag_meanings_follow_cf(results):
    attrs = results["ida"]["censored_reason"].attrs
    meanings = attrs["flag_meanings"]
    assert isinstance(meanings, str)
    assert len(meanings.split()) == len(attrs["flag_values"]) == len(rd.CENSORED_REASONS)
    for word, text in zip(meanings.split(), rd.CENSORED_REASONS.values(), strict=True):
        assert word == text.replace(" ", "_")
