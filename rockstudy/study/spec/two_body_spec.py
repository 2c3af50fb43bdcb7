"""What a study of two-body objects (``kind = "stacked"`` or ``"isolated"`` in ``[structure]
kind = "objects"``) cannot ask, checked with the whole study: their scenes run the two-body
systems (:func:`rockstudy.simulate_batch` with ``structure=``), which take Housner-type
rocking of their bodies under a horizontal ground motion, by the nonlinear equations.
"""

from __future__ import annotations

from .structures import TWO_BODY_KINDS, FieldError

__all__ = ["check_two_body"]


def _two_body_objects(study) -> list:
    """(index, object) of the study's two-body objects."""
    st = study.structure
    if st.kind != "objects":
        return []
    return [(i, o) for i, o in enumerate(st.objects) if o.kind in TWO_BODY_KINDS]


def _has_vertical(motion) -> bool:
    """Whether a record motion gives vertical components (``vertical``, or H/V pairs)."""
    files = getattr(motion, "files", None)
    pairs = isinstance(files, list) and any(not isinstance(f, str) for f in files)
    return getattr(motion, "vertical", None) is not None or pairs


def check_two_body(study) -> None:
    """A :class:`FieldError` naming the field a study of two-body objects cannot give: the
    contact model (``run.model``), a method other than ``"nonlinear"`` (``run.method``), the
    friction check (``friction``, top level or the object's) and vertical components
    (``motion.vertical`` or H/V pairs in ``motion.files``)."""
    found = _two_body_objects(study)
    if not found:
        return
    i, first = found[0]
    who = f"structure.objects[{i}] ({first.name!r}) is {first.kind}"
    if study.run.model != "rocking":
        raise FieldError(
            "run.model",
            f"{study.run.model!r} runs the contact model of a single block; {who}, whose bodies "
            "rock without sliding: give model = 'rocking', or leave it out of the study",
        )
    if study.run.method != "nonlinear":
        raise FieldError(
            "run.method",
            f"{study.run.method!r}: {who}, which runs its nonlinear equations only: give "
            "method = 'nonlinear'",
        )
    with_mu = [(j, o) for j, o in found if o.friction is not None]
    if study.friction is not None or with_mu:
        j, o = with_mu[0] if with_mu else found[0]
        field = "friction" if not with_mu else f"structure.objects[{j}].friction"
        raise FieldError(
            field,
            f"the friction check is of a single block on its base; structure.objects[{j}] "
            f"({o.name!r}) is {o.kind}: give friction on its block objects only",
        )
    if _has_vertical(study.motion):
        raise FieldError(
            "motion.vertical",
            f"{who}, whose equations take a horizontal ground motion only: leave the vertical "
            "components out",
        )
