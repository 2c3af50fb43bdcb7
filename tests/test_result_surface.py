"""The result's surface: repr, xarray and pandas export, plot, and simulate_batch as a Dataset.
Each is checked against the arrays and scalars it must carry (exact equality: an export
does not compute), and against the block's own alpha."""

import math

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")

import rockstudy as rs  # noqa: E402
from rockstudy.motions import SinePulse  # noqa: E402


@pytest.fixture(scope="module")
def rocking():
    return rs.simulate(rs.Block(1.0, 0.2), SinePulse(3.0, 0.5))


@pytest.fixture(scope="module")
def falling():
    return rs.simulate(rs.Block(1.0, 0.2), SinePulse(30.0, 1.5))


def test_repr_states_the_scalars_in_their_units(rocking, falling):
    text = repr(rocking)
    assert len(text) < 300 and "[" not in text  # no arrays
    assert f"{rocking.max_rotation:.4g} rad" in text
    assert f"{rocking.max_rotation / 0.2:.4g} x critical rotation 0.2 rad" in text
    assert f"{rocking.n_impacts} impacts" in text
    assert f"first impact {rocking.impact_times[0]:.4g} s" in text
    assert "overturned no" in text
    assert f"overturned yes, at {falling.overturn_time:.4g} s" in repr(falling)
    assert f"{math.pi / 2:.4g} rad" in repr(falling)


def test_every_result_carries_its_rocking_parameters(rocking):
    assert rocking.info["critical_rotation"] == 0.2
    assert rocking.info["frequency_parameter"] == pytest.approx(math.sqrt(3 * 9.81 / 4))
    assert rocking.info["restitution"] == pytest.approx(1 - 1.5 * math.sin(0.2) ** 2)
    assert "SinePulse" in rocking.info["motion"] and "amplitude=3.0" in rocking.info["motion"]


def test_to_xarray_round_trips_the_arrays_with_units(rocking, tmp_path):
    import xarray as xr

    ds = rocking.to_xarray()
    np.testing.assert_array_equal(ds["time"].values, rocking.t)
    np.testing.assert_array_equal(ds["theta"].values, rocking.theta)
    np.testing.assert_array_equal(ds["theta_dot"].values, rocking.theta_dot)
    np.testing.assert_array_equal(ds["impact_time"].values, rocking.impact_times)
    assert ds["impact_time"].dims == ("impact",)
    units = {k: ds[k].attrs["units"] for k in ("time", "theta", "theta_dot", "impact_time")}
    assert units == {"time": "s", "theta": "rad", "theta_dot": "rad s-1", "impact_time": "s"}
    assert all(ds[k].attrs["long_name"] for k in units)
    assert ds.attrs["max_rotation"] == rocking.max_rotation
    assert ds.attrs["n_impacts"] == rocking.n_impacts and ds.attrs["overturned"] == 0
    assert ds.attrs["method"] == "nonlinear" and ds.attrs["rtol_requested"] == 1e-8
    assert ds.attrs["critical_rotation"] == 0.2
    ds.to_netcdf(tmp_path / "r.nc")  # attributes are netCDF-ready
    back = xr.open_dataset(tmp_path / "r.nc")
    np.testing.assert_array_equal(back["theta"].values, rocking.theta)


def test_to_dataframe_is_the_history(rocking):
    df = rocking.to_dataframe()
    assert list(df.columns) == ["t", "theta", "theta_dot"]
    np.testing.assert_array_equal(df["theta"].to_numpy(), rocking.theta)
    np.testing.assert_array_equal(df["t"].to_numpy(), rocking.t)


def test_plot_draws_theta_over_alpha_with_impacts_and_overturning(rocking, falling):
    import matplotlib.pyplot as plt

    ax = rocking.plot()
    line = ax.get_lines()[0]
    x, y = line.get_xdata(), line.get_ydata()
    # the history with the exact peaks merged in (tests/test_peaks_dense.py), in time order
    assert np.all(np.diff(x) >= 0)
    drawn = set(zip(x.tolist(), y.tolist(), strict=True))
    assert set(zip(rocking.t.tolist(), (rocking.theta / 0.2).tolist(), strict=True)) <= drawn
    peaks = (rocking.peak_rotations / 0.2).tolist()
    assert set(zip(rocking.peak_times.tolist(), peaks, strict=True)) <= drawn
    impacts = [ln for ln in ax.get_lines()[1:] if ln.get_linestyle() == ":"]
    assert len(impacts) == rocking.n_impacts
    assert ax.get_lines()[1].get_xdata()[0] == rocking.impact_times[0]
    plt.close(ax.figure)
    fig, given = plt.subplots()
    ax = falling.plot(ax=given)
    assert ax is given
    cross = [ln for ln in ax.get_lines() if ln.get_label() == "overturned"]
    assert cross and cross[0].get_xdata()[0] == falling.overturn_time
    assert abs(cross[0].get_ydata()[0]) == pytest.approx((math.pi / 2) / 0.2)
    plt.close(fig)


def test_batch_as_dataset_equals_the_dict():
    kw = dict(
        half_diagonal=[0.5, 1.0, 2.0],
        slenderness=0.2,
        amplitude=[3.0, 4.0, 30.0],
        period=0.5,
    )
    plain = rs.simulate_batch(**kw)
    ds = rs.simulate_batch(**kw, as_dataset=True)
    assert set(plain) == set(ds.data_vars)
    for name, values in plain.items():
        np.testing.assert_array_equal(ds[name].values, values)
        assert ds[name].dims == ("scene",) and "units" in ds[name].attrs
    np.testing.assert_array_equal(ds["half_diagonal"].values, kw["half_diagonal"])
    np.testing.assert_array_equal(ds["amplitude"].values, kw["amplitude"])
    np.testing.assert_array_equal(ds["slenderness"].values, [0.2] * 3)
    assert ds["amplitude"].attrs["units"] == "m s-2" and ds["period"].attrs["units"] == "s"
    assert "half_diagonal" in ds.coords and ds.attrs["method"] == "nonlinear"
