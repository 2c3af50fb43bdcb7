"""One vocabulary across the public functions: ``friction=`` for the friction check, the
bootstrap keywords ``n_boot``, ``conf_level``, ``seed`` (one default each, in one order),
reports that take a Dataset or a path alike, and every public error type exported at the top.

Oracles: single-scene simulations with ``simulate(friction=)`` (the friction demand of each
design point), the shared constants of :mod:`rockstudy.study.analysis.fragility_fit`, the
classes defined in the package (found by walking its modules, not listed here), and the same
report written from a Dataset and from its saved path.
"""

import importlib
import inspect
import pkgutil
import re
import warnings

import numpy as np
import pytest

import rockstudy as rs
from rockstudy.motions import synthetic_near_fault
from rockstudy.study.analysis.fragility_fit import CONF_LEVEL, N_BOOT, SEED
from rockstudy.study.designs import records as rd
from rockstudy.study.report import make_report, record_report
from rockstudy.study.spec.design_kinds import DESIGN_KINDS

BLOCKS = [rs.Block(half_diagonal=0.6, slenderness=0.25), rs.Block(1.2, 0.2)]
LEVELS = np.array([1.0, 3.0])  # PGA [m/s^2]: below and above the uplift of both blocks
RTOL = 1e-8


@pytest.fixture(scope="module")
def record():
    return synthetic_near_fault(pulse_period=0.8, pga=3.0, seed=4, duration=4.0)


def _design(kind, record, **kw):
    """The design function of a registered kind (its ``run``), quick options."""
    if kind.levels:
        kw["levels"] = LEVELS
    if kind.capacities:
        kw.update(step=0.05, tolerance=0.02, scan=0)
    return getattr(rd, kind.run)([record], BLOCKS, rtol=RTOL, **kw)


def _scales(kind, ds):
    """The scale factor of each (structure[, level]) point of the friction check."""
    if kind.capacities:
        return ds["capacity_scale_lower"].isel(record=0).values
    if kind.levels:
        return ds["scale"].isel(record=0).values
    return np.ones(ds.sizes["structure"])


# ------------------------------------------------------------------------------ friction


@pytest.mark.parametrize("kind", list(DESIGN_KINDS.values()), ids=lambda k: k.name)
def test_the_designs_take_friction_and_give_simulates_friction_demand(kind, record):
    with warnings.catch_warnings():
        warnings.simplefilter("error", FutureWarning)  # the new spelling does not warn
        ds = _design(kind, record, friction=0.4)
    demand = ds["friction_demand"].isel(record=0).values
    scales = _scales(kind, ds)
    for j, block in enumerate(BLOCKS):
        for k, s in np.ndenumerate(np.atleast_1d(scales[j])):
            r = rs.simulate(block, record.scaled(float(s)), rtol=RTOL, friction=0.4)
            got = np.atleast_1d(demand[j])[k]
            np.testing.assert_allclose(got, r.friction_demand, rtol=1e-6)
    assert "friction_demand" not in _design(kind, record)  # no friction: no check


@pytest.mark.parametrize("kind", list(DESIGN_KINDS.values()), ids=lambda k: k.name)
def test_contact_is_a_deprecated_spelling_of_the_friction_check(kind, record):
    new = _design(kind, record, friction=0.4)
    with pytest.warns(FutureWarning, match="contact= of the record designs is deprecated"):
        old = _design(kind, record, contact=True)
    np.testing.assert_array_equal(old["friction_demand"].values, new["friction_demand"].values)
    np.testing.assert_array_equal(old["lift_off"].values, new["lift_off"].values)


@pytest.mark.parametrize(
    "friction, message",
    [
        (-0.1, r"friction must lie in \(0, 10\]"),
        (11.0, r"friction must lie in \(0, 10\]"),
        ([0.3, 0.4, 0.5], r"friction: give one number or one per structure \(2\)"),
        ("0.3", "friction must be a number"),
    ],
)
def test_a_bad_friction_of_a_design_is_named(record, friction, message):
    with pytest.raises((ValueError, TypeError), match=message):
        rd.cloud([record], BLOCKS, friction=friction)


def test_one_friction_per_structure_with_none_for_one(record):
    ds = rd.cloud([record], BLOCKS, friction=[0.3, np.nan])
    assert ds["friction_demand"].shape == (1, 2)


# ------------------------------------------------------------------------------ bootstrap


def _public_functions():
    """Every public function of the study layer (by the modules' ``__all__``)."""
    import rockstudy.study as study

    seen = {}
    for info in pkgutil.walk_packages(study.__path__, "rockstudy.study."):
        if any(part.startswith("_") for part in info.name.split(".")):
            continue
        module = importlib.import_module(info.name)
        for name in getattr(module, "__all__", ()):
            value = getattr(module, name)
            if inspect.isfunction(value):
                seen[f"{value.__module__}.{value.__name__}"] = value
    return seen


BOOT = ("n_boot", "conf_level", "seed")


def test_every_bootstrap_takes_n_boot_conf_level_seed_keyword_only_in_that_order():
    functions = {  # the functions with a bootstrap (not the checks of n_boot alone)
        k: f
        for k, f in _public_functions().items()
        if "n_boot" in _params(f) and len(_params(f)) > 1
    }
    assert {"stripe_fragility", "ida_fragility", "object_risk"} <= {
        k.rpartition(".")[2] for k in functions
    }
    defaults = {"n_boot": N_BOOT, "conf_level": CONF_LEVEL, "seed": SEED}
    bad = {}
    for name, f in functions.items():
        params = _params(f)
        given = [p for p in params if p in BOOT]
        if given != [p for p in BOOT if p in params]:
            bad[name] = f"order {given}"
        for p in given:
            if params[p].kind is not inspect.Parameter.KEYWORD_ONLY:
                bad[name] = f"{p} is not keyword-only"
            if params[p].default != defaults[p]:
                bad[name] = f"{p} defaults to {params[p].default!r}"
    assert not bad, bad


def _params(f):
    return inspect.signature(f).parameters


def test_the_bootstrap_defaults_are_the_shared_constants():
    assert (N_BOOT, CONF_LEVEL, SEED) == (200, 0.9, 0)


# ------------------------------------------------------------------------------ reports


def _html(path):
    """The page without its embedded figures (PNG bytes carry no meaning here)."""
    return re.sub(r"data:image/png;base64,[A-Za-z0-9+/=]+", "", path.read_text())


def test_both_reports_take_a_dataset_or_its_path_alike(record, tmp_path):
    ds = rd.cloud([record, record.scaled(2.0)], BLOCKS, rtol=RTOL)
    ds = ds.assign_coords(record_name=ds["record_name"].astype(str))
    cube = tmp_path / "cloud.zarr"
    ds.to_zarr(cube, consolidated=True)
    from_path = record_report(cube, tmp_path / "a", title="t", n_boot=0)
    from_data = record_report(ds, tmp_path / "b", title="t", n_boot=0)
    assert _html(from_path) == _html(from_data)
    made_path = make_report(cube, tmp_path / "c")
    made_data = make_report(ds, tmp_path / "d")
    assert "Cloud" in _html(made_data) and made_path.exists()
    with pytest.raises(ValueError, match="out: give the report's folder"):
        make_report(ds)
    for report in (record_report, make_report):
        with pytest.raises(TypeError, match="must be an xarray.Dataset or the path"):
            report(3.0, tmp_path / "e")


# ------------------------------------------------------------------------------ errors


def _error_classes():
    """Every exception class defined in a module of the package (private ones aside)."""
    found = {}
    for info in pkgutil.walk_packages(rs.__path__, "rockstudy."):
        module = importlib.import_module(info.name)
        for name, value in vars(module).items():
            if (
                inspect.isclass(value)
                and issubclass(value, Exception)
                and not issubclass(value, Warning)
                and value.__module__ == info.name
                and not name.startswith("_")
            ):
                found[name] = value
    return found


def test_every_error_type_is_exported_from_the_top():
    errors = _error_classes()
    assert {"UnitsError", "IdaOptionError", "FieldError", "StudyError"} <= set(errors)
    missing = sorted(n for n, c in errors.items() if getattr(rs, n, None) is not c)
    assert not missing, f"not exported from rockstudy: {missing}"
    assert set(errors) <= set(rs.__all__)


def test_a_study_with_friction_gives_its_rows_the_friction_check(record, tmp_path):
    """The study's ``friction`` reaches the design functions as ``friction=``: each row's
    demand is simulate(friction=)'s of the record as run (a cloud: unscaled)."""
    from rockstudy.constants import STANDARD_GRAVITY
    from rockstudy.study import validate_text
    from rockstudy.study.designs import record_rows
    from rockstudy.study.designs.sampling import make_design

    t = np.arange(record.acceleration.size) * record.dt
    np.savetxt(
        tmp_path / "r.csv",
        np.column_stack([t, record.acceleration / STANDARD_GRAVITY]),
        "%.17g",
        ",",
    )
    text = (
        'name = "f"\nseed = 1\nfriction = 0.4\n[sampler]\nkind = "lhs"\nn = 2\n'
        '[structure]\nkind = "block"\nhalf_diagonal = { dist = "uniform", low = 0.4, high = 1.2 }\n'
        'slenderness = { dist = "uniform", low = 0.15, high = 0.25 }\n'
        f'[motion]\nkind = "record"\nfiles = "{tmp_path}/*.csv"\n[design]\nkind = "cloud"\n'
    )
    study = validate_text(text, base_dir=tmp_path)
    design = make_design(study, tmp_path)
    cols = {k: design[k].values for k in design.data_vars} | {"sample": design["sample"].values}
    rows = record_rows.evaluate_rows(study, cols, tmp_path)
    for k in range(design.sizes["sample"]):
        block = rs.Block(float(design["half_diagonal"][k]), float(design["slenderness"][k]))
        r = rs.simulate(block, record, rtol=study.run.rtol, friction=0.4)
        np.testing.assert_allclose(rows["friction_demand"][k], r.friction_demand, rtol=1e-6)
