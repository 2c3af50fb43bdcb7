"""``[design] damage_states`` run by a study: an IDA study stores the state capacities of
:func:`incremental_dynamic_analysis` on the same records and objects (the API as oracle), on
(damage_state, record, structure) with the states named; a cloud keeps the states for the
fits."""

import numpy as np
from _helpers import write_at2

from rockstudy.motions import stochastic_record
from rockstudy.study.designs.records import incremental_dynamic_analysis

STUDY = """
name = "museum_states"
seed = 1
structure = {{ kind = "objects", file = "objects.csv" }}
motion = {{ kind = "record", files = "{folder}" }}
[design]
kind = "{kind}"
damage_states = {{ chipped = 0.2, displaced = 0.5, overturned = 1.0 }}
{options}
"""
IDA = 'im = "pga"\nstep = 0.05\ntolerance = 0.01\nmax_pga_ratio = 3.0\nscan = 2'
OBJECTS = "name,half_diagonal,slenderness\nBronze,0.5,0.35\nStatue,0.8,0.2\n"
STATES = {"chipped": 0.2, "displaced": 0.5, "overturned": 1.0}


def _run(tmp_path, kind, options=""):
    """The stored result of the study of ``kind`` on two records and the two objects."""
    from distributed import Client

    from rockstudy.study import load_study, run_study
    from rockstudy.study.running.store import open_result

    folder = tmp_path / "records"
    folder.mkdir(exist_ok=True)
    for seed in (11, 12):
        write_at2(folder / f"r{seed}.AT2", stochastic_record(3.0, duration=3.0, seed=seed))
    (tmp_path / "objects.csv").write_text(OBJECTS)
    path = tmp_path / f"{kind}.toml"
    path.write_text(STUDY.format(folder=folder, kind=kind, options=options))
    cube = tmp_path / f"{kind}.zarr"
    with Client(processes=False, n_workers=1, threads_per_worker=1, dashboard_address=None) as c:
        run_study(load_study(path), cube, client=c, base_dir=tmp_path, progress=False)
    return open_result(cube).load(), folder


def test_an_ida_study_stores_the_state_capacities_of_the_api(tmp_path):
    from rockstudy.motions import load_suite

    ds, folder = _run(tmp_path, "ida", IDA)
    api = incremental_dynamic_analysis(
        load_suite(str(folder)),
        {"half_diagonal": [0.5, 0.8], "slenderness": [0.35, 0.2]},
        im="pga", step=0.05, tolerance=0.01, max_pga_ratio=3.0, scan=2, damage_states=STATES,
    )  # fmt: skip
    assert ds["state_capacity"].dims == ("damage_state", "record", "structure")
    assert list(ds["damage_state"].values) == list(STATES)
    assert list(ds["damage_limit"].values) == [0.2, 0.5, 1.0]
    for name in ("capacity", "state_capacity", "state_capacity_scale"):
        np.testing.assert_allclose(ds[name].values, api[name].values, rtol=1e-12, err_msg=name)
    assert np.isfinite(ds["state_capacity"].sel(damage_state="chipped").values).all()
    assert ds.attrs["damage_states"] == api.attrs["damage_states"]


def test_a_cloud_study_keeps_its_damage_states_for_the_fits(tmp_path):
    from rockstudy.study.spec.damage_states import damage_states

    ds, _ = _run(tmp_path, "cloud")
    states = damage_states(ds.attrs["damage_states"])
    assert [(s.name, s.limit) for s in states] == list(STATES.items())
    assert "max_rotation" in ds and "critical_rotation" in ds
