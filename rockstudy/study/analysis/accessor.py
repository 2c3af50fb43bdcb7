"""The ``rocking`` accessor of :class:`xarray.Dataset`: a result cube analyses itself.

``import rockstudy.study`` (or anything under it, e.g. ``from rockstudy.study import
open_result``) registers it, so that any result cube opened with xarray offers
``ds.rocking.fragility(...)``, ``ds.rocking.sobol(...)``, ``ds.rocking.collapse(...)`` and the
others. Each method delegates to the analysis that fits the cube's kind (:attr:`kind`: the
sampler of a study, or the record design) and refuses, with a ValueError naming it, a keyword
that does not apply to that kind. The accessor computes nothing itself.

A record study's cube read with ``xarray.open_zarr`` is in the store's layout (one row per
scene, on ``sample``); the accessor folds it into the layout of the record designs
(:func:`~rockstudy.study.designs.record_rows.design_dataset`, as
:func:`~rockstudy.study.open_result` does) before it analyses it.

A record design over floors (``[motion] floor = [..]``) or orientations (``[design]
orientations``) is fitted on every floor and orientation apart, the result carrying the
dimensions ``floor`` and ``orientation`` (:mod:`~rockstudy.study.analysis.motion_axes`);
``orientation="worst"`` or ``"median"`` fits the worst orientation or the median over
orientations instead (:func:`~rockstudy.study.analysis.orientations.orientation_summary`).
"""

from __future__ import annotations

import inspect
from functools import cached_property

import xarray as xr

from ... import _validate
from ..designs.record_rows import design_dataset
from ..spec.design_kinds import DESIGN_KINDS, design_kind
from ..spec.schema import Study
from . import contact, record_fragility, record_similarity, risk, sampled
from .orientations import ORIENTATION_SUMMARIES, orientation_summary

__all__ = ["RECORD_DESIGNS", "RockingAccessor"]

#: The kinds of record designs (``attrs["design"]`` of their datasets): the registry's.
RECORD_DESIGNS = tuple(DESIGN_KINDS)


def _takes(function, renamed=(), leave=()) -> list[str]:
    """The keywords of ``function`` but ``ds`` and ``leave`` (``renamed``: (its name, ours))."""
    names = [p for p in inspect.signature(function).parameters if p not in ("ds", "kw", *leave)]
    return [dict(renamed).get(p, p) for p in names]


def _keywords(method: str, kind: str, function, given, takes=None) -> None:
    """A ValueError naming the first keyword of ``given`` that ``function`` does not take
    (``takes``: the keywords it does take, default its signature's)."""
    takes = _takes(function) if takes is None else takes
    for name in given:
        if name not in takes:
            raise ValueError(
                f"ds.rocking.{method}: {name!r} does not apply to a {kind!r} cube "
                f"({function.__name__}); its keywords are {takes}"
            )


@xr.register_dataset_accessor("rocking")
class RockingAccessor:
    """The analyses of a rockstudy result cube, as ``ds.rocking``.

    A cube is either a study's cube (its ``study`` attribute: the normalised study file; the
    kind is the sampler's, ``"monte_carlo"``, ``"lhs"``, ``"sobol"`` or ``"grid"``, or the
    record design's for a record study) or a record design's dataset made in Python
    (``attrs["design"]``: ``"cloud"``, ``"stripes"`` or ``"ida"``). On any other Dataset the
    accessor's methods raise a ValueError naming what is missing.

    Examples
    --------
    >>> import xarray as xr
    >>> import rockstudy.study  # registers ds.rocking
    >>> ds = xr.open_zarr("results/quickstart.zarr")
    >>> ds.rocking.kind
    'monte_carlo'
    >>> ds.rocking.fragility("amplitude_ratio", by="half_diagonal", bins=[0.5, 1, 2, 3])
    """

    def __init__(self, ds: xr.Dataset):
        self._raw = ds

    @cached_property
    def _ds(self) -> xr.Dataset:
        """The cube in the layout its analyses read (a record study's rows folded); a
        ValueError if it is not a cube (:attr:`kind`)."""
        self.kind  # noqa: B018 - refuses a Dataset that is not a cube
        ds = self._raw
        if "record_design" in ds.attrs and "sample" in ds.dims:
            return design_dataset(ds)
        return ds

    @cached_property
    def kind(self) -> str:
        """The cube's kind: a record design (``"cloud"``, ``"stripes"``, ``"ida"``) or the
        sampler of its study (``"monte_carlo"``, ``"lhs"``, ``"sobol"``, ``"grid"``).

        Examples
        --------
        >>> ds.rocking.kind
        'ida'
        """
        attrs = self._raw.attrs
        design = attrs.get("design", attrs.get("record_design"))
        if design is not None:
            if design not in RECORD_DESIGNS:
                raise ValueError(
                    f"ds.rocking: attrs['design'] must be one of {list(RECORD_DESIGNS)}, "
                    f"got {design!r}"
                )
            return design
        if "study" not in attrs:
            raise ValueError(
                "ds.rocking: not a rockstudy result cube: it has no 'study' attribute (the "
                "study file a run stores in its cube) and no 'design' attribute (one of "
                f"{list(RECORD_DESIGNS)}, set by the record designs)"
            )
        return self.study.sampler.kind

    @cached_property
    def study(self) -> Study:
        """The :class:`~rockstudy.study.Study` the cube was run from (its ``study`` attribute).

        Examples
        --------
        >>> ds.rocking.study.sampler.n
        20000
        """
        if "study" not in self._raw.attrs:
            raise ValueError(
                "ds.rocking.study: the cube has no 'study' attribute: it was not written by "
                "a study run (a record design made in Python carries none)"
            )
        try:
            return sampled.study_of(self._raw)
        except ValueError as exc:
            raise ValueError(f"ds.rocking.study: {exc}") from None

    def _records(self, method: str) -> str:
        """The kind of a record design, or a ValueError naming ``method``."""
        if self.kind not in RECORD_DESIGNS:
            raise ValueError(
                f"ds.rocking.{method}: needs a record design ({list(RECORD_DESIGNS)}); this "
                f"is a {self.kind!r} cube"
            )
        return self.kind

    @property
    def _record_fit(self):
        """The fragility fit of a record design: of IDA capacities, or of stripes' points."""
        return getattr(record_fragility, design_kind(self.kind).fragility)

    def _oriented(self, method: str, orientation) -> xr.Dataset:
        """The cube, or with ``orientation`` ("worst" or "median") its summary over the
        orientations (:func:`~rockstudy.study.analysis.orientations.orientation_summary`);
        a ValueError naming ``method`` for another value or a cube without orientations."""
        if orientation is None:
            return self._ds
        if orientation not in ORIENTATION_SUMMARIES:
            raise ValueError(
                f"ds.rocking.{method}: orientation: must be one of "
                f"{list(ORIENTATION_SUMMARIES)} (or None: one fit per orientation), got "
                f"{orientation!r}"
            )
        if "orientation" not in self._ds.dims:
            raise ValueError(
                f"ds.rocking.{method}: orientation={orientation!r}: the cube has no "
                "'orientation' dimension (a record design with [design] orientations); leave "
                "orientation out"
            )
        return orientation_summary(self._ds, orientation)

    def _sampled(self, method: str, record_analysis: str) -> str:
        """The sampler kind of a sampled cube, or a ValueError naming ``method``."""
        if self.kind in RECORD_DESIGNS:
            raise ValueError(
                f"ds.rocking.{method}: applies to sampled studies (Monte Carlo, Sobol', ...); "
                f"this is a {self.kind!r} record design: use {record_analysis}"
            )
        return self.kind

    # -------------------------------------------------------------------------- fragility

    def fragility(self, im: str | None = None, by=None, orientation=None, **kw):
        """Lognormal fragility of the cube, by the fit its kind calls for.

        - a sampled study (Monte Carlo, LHS, Sobol'): the Bernoulli MLE of every sample
          (:func:`rockstudy.study.analysis.fragility`; ``im`` is its ``intensity``);
        - stripes or a cloud: the binomial MLE of the points, bands by record
          (:func:`rockstudy.study.stripe_fragility`);
        - an IDA: the lognormal fit of the capacities, censored ones included
          (:func:`rockstudy.study.ida_fragility`).

        All go through :mod:`rockstudy.study.analysis.fragility_fit`.

        Parameters
        ----------
        im : str, optional
            The intensity: a variable of a sampled cube (required there, e.g.
            ``"amplitude_ratio"``), or a measure of a record design (default the design's own).
        by : str, optional
            One curve per value (or per bin, with ``bins``) of this variable: on ``sample``
            for a sampled cube, ``"structure"`` or a variable on ``structure`` for a record
            design.
        orientation : {None, "worst", "median"}
            A record design over orientations: None (default) fits every orientation
            apart (the dimension an outer level of the result, as ``floor`` is); "worst"
            or "median" fits the worst orientation or the median over orientations
            (:func:`~rockstudy.study.analysis.orientations.orientation_summary`).
        **kw
            The other keywords of the fit: ``bins``, ``n_boot``, ``conf_level``, ``seed``;
            ``outcome`` and ``failed`` (sampled only); ``period`` (record designs only). A
            keyword that does not apply to the cube's kind is a ValueError naming it.

        Returns
        -------
        pandas.DataFrame
            One row per group: ``theta``, ``beta`` (the MLE), their intervals, ``n``, the
            observed range and the band columns of
            :func:`~rockstudy.study.analysis.fragility_fit.fragility_row`; over floors and
            orientations, one per floor and orientation too (outer index levels ``floor``,
            ``orientation``).

        Examples
        --------
        >>> ds.rocking.fragility("amplitude_ratio", by="half_diagonal", bins=[0.5, 1, 2, 3])
        >>> ida.rocking.fragility(im="pgv_ratio", by="structure")
        """
        if self.kind in RECORD_DESIGNS:
            _keywords("fragility", self.kind, self._record_fit, kw)
            return self._record_fit(self._oriented("fragility", orientation), im=im, by=by, **kw)
        takes = _takes(sampled.fragility, {"intensity": "im"})
        _keywords("fragility", self.kind, sampled.fragility, kw, takes)
        self._oriented("fragility", orientation)  # a sampled cube has no orientations
        if im is None:
            outputs = set(self.study.run.outputs) | {"status", "kernel_status", "error"}
            inputs = [
                str(n)
                for n, v in self._ds.data_vars.items()
                if v.dims == ("sample",) and v.dtype.kind == "f" and n not in outputs
            ]
            raise ValueError(
                f"ds.rocking.fragility: im is required for a {self.kind!r} cube: name its "
                f"intensity variable, one of the cube's inputs {inputs}"
            )
        sampled.check_variables(self._ds, im=im)
        return sampled.fragility(self._ds, im, by=by, **kw)

    def efficiency(self, candidates=None, by=None, orientation=None, **kw):
        """Which intensity measure predicts overturning best, on a record design
        (:func:`rockstudy.study.im_efficiency`): the dispersion of each, per scaling power.

        Parameters
        ----------
        candidates : sequence, optional
            Measures (``"sa"`` expands to every stored period) or ``(name, period)`` pairs;
            default every stored measure that scales, the ratios and the pulse group.
        by, orientation : str, optional
            As in :meth:`fragility`.
        **kw
            ``bins``, ``n_boot``, and the fit's ``conf_level`` and ``seed``.

        Returns
        -------
        pandas.DataFrame
            Indexed by (``im``, group), sorted by ``beta_linear`` within each group.

        Examples
        --------
        >>> ds.rocking.efficiency(["pga", "pgv", "pgv_ratio"])
        """
        kind = self._records("efficiency")
        takes = _takes(record_fragility.im_efficiency) + _takes(
            self._record_fit, leave=("im", "period", "by", "bins", "n_boot")
        )
        _keywords("efficiency", kind, record_fragility.im_efficiency, kw, takes)
        ds = self._oriented("efficiency", orientation)
        return record_fragility.im_efficiency(ds, candidates, by=by, **kw)

    def risk(self, hazard=None, orientation=None, **kw):
        """Each object's annual rate and probability of overturning at a site
        (:func:`rockstudy.study.object_risk`), on a record design.

        Parameters
        ----------
        hazard : rockstudy.risk.HazardCurve, optional
            The site's hazard curve; default the study's ``[hazard]`` (and its ``years``).
        orientation : {None, "worst", "median"}
            As in :meth:`fragility`.
        **kw
            ``years``, ``n_boot``, ``conf_level``, ``seed``, ``min_overturning``.

        Returns
        -------
        xarray.Dataset
            On ``structure``, ranked by ``annual_rate``; over floors and orientations, also on
            ``floor`` and ``orientation``, the structures in the design's order.

        Examples
        --------
        >>> from rockstudy.risk import HazardCurve
        >>> ds.rocking.risk(HazardCurve.power_law(1e-4, 2.5, im="pga", units="g"), years=50)
        """
        kind = self._records("risk")
        _keywords("risk", kind, risk.object_risk, kw)
        if hazard is None:
            spec = self.study.hazard if "study" in self._raw.attrs else None
            if spec is None:
                raise ValueError(
                    "ds.rocking.risk: hazard is required: the cube's study has no [hazard]"
                )
            hazard = spec.curve()
            kw.setdefault("years", spec.years)
        return risk.object_risk(self._oriented("risk", orientation), hazard, **kw)

    # -------------------------------------------------------------------------- sensitivity

    def sobol(self, output: str, **kw):
        """First-order and total Sobol' indices of ``output`` with bootstrap intervals
        (:func:`rockstudy.study.analysis.sobol_indices`), on a Sobol' study's cube.

        Parameters
        ----------
        output : str
            The output variable, e.g. ``"max_rotation_ratio"`` or ``"overturned"``.
        **kw
            ``names``, ``second_order``, ``failed``, ``num_resamples``, ``conf_level``,
            ``seed``.

        Returns
        -------
        pandas.DataFrame
            Index: the inputs; columns ``S1``, ``S1_conf``, ``ST``, ``ST_conf``.

        Examples
        --------
        >>> ds.rocking.sobol("max_rotation_ratio", num_resamples=200)
        """
        self._sampled("sobol", "fragility or efficiency")
        _keywords("sobol", self.kind, sampled.sobol_indices, kw)
        return sampled.sobol_indices(self._ds, output, **kw)

    def sobol_convergence(self, output: str, **kw):
        """Sobol' indices on nested prefixes N = 2^k of the base samples
        (:func:`rockstudy.study.analysis.sobol_convergence`), on a Sobol' study's cube.

        Parameters
        ----------
        output : str
            The output variable.
        **kw
            ``names``, ``second_order``, ``failed``, and ``num_resamples``, ``conf_level``,
            ``seed`` of :meth:`sobol`.

        Returns
        -------
        pandas.DataFrame
            Indexed by (``N``, input), the columns of :meth:`sobol`.

        Examples
        --------
        >>> ds.rocking.sobol_convergence("overturned", num_resamples=50)
        """
        kind = self._sampled("sobol_convergence", "fragility or efficiency")
        takes = _takes(sampled.sobol_convergence) + _takes(
            sampled.sobol_indices, leave=("output", "names", "second_order", "failed")
        )
        _keywords("sobol_convergence", kind, sampled.sobol_convergence, kw, takes)
        if kind != "sobol" and kw.get("names") is None:
            raise ValueError("Sobol' indices need a sobol study (Saltelli design)")
        return sampled.sobol_convergence(self._ds, output, **kw)

    def first_order_given_data(self, output: str, variables, **kw):
        """First-order indices of ``output`` on any variables of a sampled cube, e.g. the
        dimensionless groups (:func:`rockstudy.study.analysis.first_order_given_data`).

        Parameters
        ----------
        output : str
            The output variable.
        variables : list of str
            Variables of the cube (not necessarily the sampler's inputs).
        **kw
            ``failed``, ``seed``.

        Returns
        -------
        pandas.DataFrame
            Index: the variables; columns ``S1``, ``S1_conf`` (RBD-FAST).

        Examples
        --------
        >>> ds.rocking.first_order_given_data("max_rotation_ratio", ["omega", "uplift_ratio"])
        """
        kind = self._sampled("first_order_given_data", "efficiency")
        _keywords("first_order_given_data", kind, sampled.first_order_given_data, kw)
        return sampled.first_order_given_data(self._ds, output, variables, **kw)

    # -------------------------------------------------------------------------- similarity

    def collapse(self, response: str | None = None, groups=None, **kw):
        """How far the response collapses onto the dimensionless groups (self-similarity).

        - a sampled study: the share of the variance of ``response`` within sets of samples
          sharing their point of ``groups``
          (:func:`rockstudy.study.analysis.collapse_metric`; a replicated design, ``[sampler]
          replicates = k``; on other designs use :meth:`unexplained_share`);
        - a record design: the median overturning intensity of each block size class in the
          measure ``im`` and its spread across classes
          (:func:`~rockstudy.study.analysis.record_similarity.size_class_medians`).

        Parameters
        ----------
        response, groups : str, list of str
            Sampled cubes only (both required there): the response variable and the groups.
        **kw
            Sampled: ``decimals``, ``failed``. Record designs: ``im`` (default the design's
            own measure), ``period``, ``size_bins``, ``frequency_bins``, ``n_boot``,
            ``conf_level``, ``seed``.

        Returns
        -------
        float or (pandas.DataFrame, pandas.DataFrame)
            The collapse metric (0: self-similar, ~1: the groups explain nothing); for a record
            design, the medians per (frequency band, size class) and their spread.

        Examples
        --------
        >>> rep = xr.open_zarr("replicated.zarr")  # a study with [sampler] replicates = 4
        >>> rep.rocking.collapse("max_rotation_ratio", ["a", "omega", "restitution"])
        >>> medians, spread = ida.rocking.collapse(im="pgv_ratio", size_bins=3)
        """
        if self.kind in RECORD_DESIGNS:
            for name, value in (("response", response), ("groups", groups)):
                if value is not None:
                    raise ValueError(
                        f"ds.rocking.collapse: {name!r} does not apply to a {self.kind!r} "
                        "record design; give im (the measure whose medians are compared)"
                    )
            _keywords("collapse", self.kind, record_similarity.size_class_medians, kw)
            kw.setdefault("im", self._raw.attrs.get("im", "pga"))
            return record_similarity.size_class_medians(self._ds, **kw)
        _keywords("collapse", self.kind, sampled.collapse_metric, kw)
        if response is None or groups is None:
            raise ValueError(
                f"ds.rocking.collapse: response and groups are required for a {self.kind!r} "
                "cube (e.g. 'max_rotation_ratio' and ['a', 'omega', 'restitution'])"
            )
        return sampled.collapse_metric(self._ds, response, groups, **kw)

    def unexplained_share(self, response: str, groups, **kw):
        """The share of the variance of ``response`` left by a smooth fit over ``groups``, next
        to that fit's floor (:func:`rockstudy.study.analysis.unexplained_share`): the
        self-similarity check of a sampled design that is not replicated.

        Parameters
        ----------
        response : str
            The response variable.
        groups : list of str
            The groups it should be a function of.
        **kw
            ``k`` (neighbours), ``failed``, ``log_groups``.

        Returns
        -------
        UnexplainedShare
            ``(value, floor, n, k)``.

        Examples
        --------
        >>> ds.rocking.unexplained_share("max_rotation_ratio", ["a", "omega", "restitution"])
        """
        kind = self._sampled("unexplained_share", "collapse")
        _keywords("unexplained_share", kind, sampled.unexplained_share, kw)
        return sampled.unexplained_share(self._ds, response, groups, **kw)

    # -------------------------------------------------------------------------- contact

    def contact(self, friction=None) -> xr.DataArray:
        """True for each scene outside the rocking-block model: its friction demand exceeds the
        friction coefficient, or the block lifts off
        (:func:`~rockstudy.study.analysis.contact.outside_model`).

        Parameters
        ----------
        friction : float or array_like, optional
            mu, one or one per structure (NaN: none); default the study's ``friction``.

        Returns
        -------
        xarray.DataArray
            Boolean, on the scenes of the cube.

        Examples
        --------
        >>> int(ds.rocking.contact(0.5).sum())  # scenes that would slide or lift off
        """
        if friction is None:
            mu = self.study.friction_coefficients() if "study" in self._raw.attrs else None
            if mu is None:
                raise ValueError(
                    "ds.rocking.contact: friction is required: the cube's study gives no "
                    "friction coefficient"
                )
            friction = mu
        return contact.outside_model(self._ds, _validate.numbers_array("friction", friction))
