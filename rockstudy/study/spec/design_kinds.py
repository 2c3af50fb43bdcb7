"""The kinds of record design, in one registry: what each makes, how it is fitted and how the
reports show it.

A record design runs every record of a suite against every structure: a ``cloud`` (the records
as recorded), ``stripes`` (each record scaled to each level of a grid) or an ``ida`` (each
structure's first overturning scale under each record, by a ladder refined by bisection).
Every layer that treats the kinds differently reads its :class:`DesignKind` here, never the
kind's name: the schema's ``design.kind`` (:data:`DESIGN_KINDS`), the rows of a study
(:mod:`rockstudy.study.designs.record_rows`), the fragility fits, the medians of the size
classes and the annual rates (:mod:`rockstudy.study.analysis`) and both reports
(:mod:`rockstudy.study.report`). A new kind is one entry here (and its own new code: the
function that runs it, and a fitter if none of the existing ones applies).

The entries name their functions in the layers above this one (which this module cannot
import: a study's flow runs spec -> designs -> running -> analysis -> report); each layer
looks the name up in its own module. ``tests/test_design_registry.py`` checks that every name
is there, and ``tests/test_architecture.py`` that no other module selects by a kind's name.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

__all__ = ["DESIGN_KINDS", "DesignKind", "design_kind", "kind_of"]


@dataclass(frozen=True)
class DesignKind:
    """One kind of record design.

    Attributes
    ----------
    name : str
        ``design.kind`` of a study file and ``attrs["design"]`` of the Dataset.
    description : str
        The kind in words (the summary of a report).
    scaled : bool
        Whether the records are scaled (False: run as recorded, at scale 1).
    levels : bool
        Whether the points lie on the levels of ``motion.scale_to.value`` (a ``level``
        dimension, and a ``scale`` variable: the factor of each record at each level).
    capacities : bool
        Whether the design gives each structure's first overturning capacity under each
        record (on record x structure, with the IDA's options, its ``step`` dimension of
        simulated points and censored capacities); else the outcome of each point
        (``overturned``).
    run : str
        The function of :mod:`rockstudy.study.designs.records` that runs it.
    fragility : str
        Its fragility fitter in :mod:`rockstudy.study.analysis.record_fragility`.
    risk_fitter : str
        Its fitter of the annual rates in :mod:`rockstudy.study.analysis.risk`.
    capacity : str
        The function of :mod:`rockstudy.study.report.objects` that tabulates each object's
        capacity under each record.
    draw : str
        The function of :mod:`rockstudy.study.report.objects` that draws one record's points
        of one structure (its responses).
    scale_variable : str or None
        The variable of the scale factors the report checks against ``max_scale_factor``
        (None: the records are not scaled).
    sections : tuple of str
        The titles of the report sections only this kind has.
    text : mapping
        The report's words for it: ``heading`` (its responses section), ``points`` (what
        the responses figure shows), ``points_note``, ``observed`` (the data beside a fitted
        curve), ``fit`` (what the fragility is a fit of), ``scaled`` (what the scale factors
        are of), ``objects`` (the heading of the per-object curves; "" for none),
        ``objects_note`` and ``friction`` (which scene the contact check is of; "" for each
        point).
    """

    name: str
    description: str
    scaled: bool
    levels: bool
    capacities: bool
    run: str
    fragility: str
    risk_fitter: str
    capacity: str
    draw: str
    scale_variable: str | None
    sections: tuple[str, ...] = ()
    text: Mapping[str, str] = field(default_factory=dict)


_OUTCOME_NOTE = "; open circles: stood"
#: The record designs, by name (``design.kind``).
DESIGN_KINDS: Mapping[str, DesignKind] = MappingProxyType(
    {
        "cloud": DesignKind(
            name="cloud",
            description="cloud (records unscaled)",
            scaled=False,
            levels=False,
            capacities=False,
            run="cloud",
            fragility="stripe_fragility",
            risk_fitter="stripe_fitter",
            capacity="_cloud_capacity",
            draw="_cloud_point",
            scale_variable=None,
            text={
                "heading": "Cloud",
                "points": "The cloud: each record unscaled",
                "points_note": _OUTCOME_NOTE,
                "observed": "each record's outcome (0 stood, 1 overturned)",
                "fit": "the binomial maximum-likelihood fit (Baker 2015)",
                "scaled": "",
                "objects": "",
                "objects_note": "",
                "friction": "",
            },
        ),
        "stripes": DesignKind(
            name="stripes",
            description="multiple-stripe analysis",
            scaled=True,
            levels=True,
            capacities=False,
            run="multiple_stripes",
            fragility="stripe_fragility",
            risk_fitter="stripe_fitter",
            capacity="_stripe_capacity",
            draw="_stripe_points",
            scale_variable="scale",
            text={
                "heading": "Stripes",
                "points": "Stripe points: each record scaled to each level",
                "points_note": _OUTCOME_NOTE,
                "observed": "the share of its records that overturned at each stripe level",
                "fit": "the binomial maximum-likelihood fit (Baker 2015)",
                "scaled": "stripe points",
                "objects": "Stripes of each object",
                "objects_note": "the stripe points (open circles: stood; crosses: overturned, "
                "drawn at theta_max / alpha = 1)",
                "friction": "",
            },
        ),
        "ida": DesignKind(
            name="ida",
            description="incremental dynamic analysis (a ladder of rungs, refined by bisection)",
            scaled=True,
            levels=False,
            capacities=True,
            run="incremental_dynamic_analysis",
            fragility="ida_fragility",
            risk_fitter="ida_fitter",
            capacity="_ida_capacity",
            draw="_ida_curve",
            scale_variable="capacity_scale",
            sections=("Switch band",),
            text={
                "heading": "IDA curves",
                "points": "IDA curves: every simulated scale of each record, in the order of "
                "intensity",
                "points_note": "; the line ends at the first overturning, open circles mark the "
                "scales above it at which the block was seen to survive, shaded: the switch "
                "band; the axis spans the capacities and the uplift level (the scan and switch "
                "bands above them run off the top, the scan's crosses faint)",
                "observed": "its capacities at the plotting positions (k - 1/2) / n of their ranks",
                "fit": "the fit of the IDA capacities (first overturning levels)",
                "scaled": "capacities (first overturnings)",
                "objects": "IDA curves of each object",
                "objects_note": "the IDA curves, each record's simulated scales in increasing "
                "order up to the first overturning (the line ends there); crosses: the first "
                "overturning (drawn at theta_max / alpha = 1), faint: the scales of the scan "
                "above it that overturned too; open circles: scales above the first "
                "overturning at which the object stood; shaded: the switch band from the first "
                "overturning to the highest scale at which it stood; the axis spans the "
                "capacities and uplift level (the scan and switch bands above them run off the "
                "top)",
                "friction": " (IDA: at the highest scale below the first overturning)",
            },
        ),
    }
)


def design_kind(name) -> DesignKind:
    """The entry of the design kind ``name``; a ValueError naming the kinds if there is none."""
    try:
        return DESIGN_KINDS[name]
    except (KeyError, TypeError):  # TypeError: an unhashable name
        raise ValueError(f"design kind must be one of {list(DESIGN_KINDS)}, got {name!r}") from None


def kind_of(ds, what: str = "ds", default: str | None = None) -> DesignKind:
    """The entry of a record design's Dataset (its ``attrs["design"]``; ``default`` where it
    has none); a ValueError naming ``what`` and the kinds if it is none of them."""
    name = ds.attrs.get("design", default)
    if not isinstance(name, str) or name not in DESIGN_KINDS:
        raise ValueError(
            f"{what}: attrs['design'] must be one of {list(DESIGN_KINDS)}, got {name!r}"
        )
    return DESIGN_KINDS[name]
