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
    ticks = [ln for ln in ax.get_lines() if ln.get_marker() == "|"]
    assert len(ticks) == 1  # one artist: a tick per impact, at theta = 0 where it happens
    np.testing.assert_array_equal(ticks[0].get_xdata(), rocking.impact_times)
    np.testing.assert_array_equal(ticks[0].get_ydata(), np.zeros(rocking.n_impacts))
    plt.close(ax.figure)
    fig, given = plt.subplots()
    ax = falling.plot(ax=given)
    assert ax is given
    # the cross where |theta| last passes theta_cr, between the two samples of the history
    # around it, on the side of the fall; the axis shows the rocking up to 1.15 theta_cr
    cross = [ln for ln in ax.get_lines() if ln.get_label().startswith("overturned")]
    inside = np.flatnonzero(np.abs(falling.theta) < 0.2)[-1]
    t_cr = cross[0].get_xdata()[0]
    assert falling.t[inside] <= t_cr <= falling.t[inside + 1]
    assert cross[0].get_ydata()[0] == np.sign(falling.theta[-1])
    assert ax.get_ylim() == pytest.approx((-1.15, 1.15))
    dashed = sorted(ln.get_ydata()[0] for ln in ax.get_lines() if ln.get_linestyle() == "--")
    assert dashed == [-1.0, 1.0]  # |theta| = theta_cr
    plt.close(fig)
    ax = rocking.plot()  # a rocking without a fall: the axis spans 1.2 times its peak
    assert ax.get_ylim() == pytest.approx((-1.2 * rocking.max_rotation / 0.2,) * 2 * np.r_[1, -1])
    plt.close(ax.figure)


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


def test_plot_stays_readable_with_many_impacts():
    """Over 150 impacts: short ticks (one marker per impact, no full-height line), a title
    with the names, the labels inside the figure after drawing (constrained layout), and a
    ground panel on the same time axis that is the record itself (linear between samples)."""
    from rockstudy.motions import stochastic_record

    record = stochastic_record(0.2 * 9.81, duration=20.0, seed=3)
    r = rs.simulate(rs.Block(1.0, 0.15, 0.9), record)
    assert r.n_impacts >= 150
    ax = r.plot(ground=True, structure="Statue A")
    fig = ax.figure
    assert len(fig.axes) == 2
    ground = fig.axes[1]
    assert ground.get_shared_x_axes().joined(ax, ground)
    ticks = [ln for ln in ax.get_lines() if ln.get_marker() == "|"]
    assert len(ticks) == 1 and ticks[0].get_xdata().size == r.n_impacts
    # no full-height line (an axvline spans the axes in the x-axis transform)
    assert not [ln for ln in ax.get_lines() if ln.get_transform() is ax.get_xaxis_transform()]
    assert ax.get_title() == f"Statue A under {record.name}"
    assert ground.get_ylabel() == "a_g [m/s^2]" and ground.get_xlabel() == "time t [s]"
    t, a = ground.get_lines()[0].get_data()
    assert t[-1] >= record.duration
    inside = t <= record.time[-1]
    np.testing.assert_allclose(
        a[inside], np.interp(t[inside], record.time, record.acceleration), rtol=0, atol=1e-12
    )
    fig.canvas.draw()
    box = fig.bbox
    for axes in fig.axes:
        for label in (axes.yaxis.label, axes.xaxis.label, axes.title):
            if label.get_text():
                ext = label.get_window_extent()
                assert box.x0 <= ext.x0 and ext.x1 <= box.x1, label.get_text()
                assert box.y0 <= ext.y0 and ext.y1 <= box.y1, label.get_text()
    import matplotlib.pyplot as plt

    plt.close(fig)


def test_plot_names_and_ground_refusals(rocking):
    import matplotlib.pyplot as plt

    ax = rocking.plot(structure="Column 2", motion="design pulse")
    assert ax.get_title() == "Column 2 under design pulse"
    assert len(ax.figure.axes) == 1
    plt.close(ax.figure)
    ax = rocking.plot()
    assert ax.get_title().startswith("Block(half_diagonal=1.0, slenderness=0.2")
    assert "SinePulse(amplitude=3.0, period=0.5" in ax.get_title()
    plt.close(ax.figure)
    ax = rocking.plot(ground=SinePulse(3.0, 0.5))
    t, a = ax.figure.axes[1].get_lines()[0].get_data()
    np.testing.assert_allclose(
        a, np.where(t <= 0.5, 3.0 * np.sin(2 * np.pi * t / 0.5), 0.0), atol=1e-12
    )
    plt.close(ax.figure)
    fig, given = plt.subplots()
    with pytest.raises(ValueError, match="ground"):
        rocking.plot(ax=given, ground=True)
    with pytest.raises(TypeError, match="ground must be"):
        rocking.plot(ground="yes")
    orphan = rs.RockingResult(
        rocking.t,
        rocking.theta,
        rocking.theta_dot,
        0.1,
        False,
        rocking.impact_times,
        math.nan,
        "nonlinear",
    )
    with pytest.raises(ValueError, match="does not hold its motion"):
        orphan.plot(ground=True)
    plt.close(fig)
