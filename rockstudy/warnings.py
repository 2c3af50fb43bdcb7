"""Warning classes: a method is asked to work where its measured accuracy is poor.

All derive from :class:`AccuracyWarning`, so ``warnings.simplefilter("error", AccuracyWarning)``
turns every one of them into an error. They live here, in ``rockstudy.warnings``; the top-level
names (``rockstudy.AccuracyWarning``, ...) are the same classes.
"""

__all__ = [
    "AccuracyWarning",
    "LinearizationWarning",
    "ClosedFormValidityWarning",
    "ComplexAccuracyWarning",
    "ComplexFromRestWarning",
    "LooseToleranceWarning",
    "IncompleteReferenceWarning",
    "EquivalentBlockWarning",
    "ContactWarning",
    "SeparationWarning",
    "UpliftWarning",
    "UnitsWarning",
]


class AccuracyWarning(RuntimeWarning):
    """A result is outside the range where the method was measured to be accurate."""


class LinearizationWarning(AccuracyWarning):
    """The linearized model (3.1) of [000] was run where its error bound is large or unknown."""


class ClosedFormValidityWarning(AccuracyWarning):
    """A closed form of [000] was evaluated outside the region where it is exact."""


class ComplexAccuracyWarning(AccuracyWarning):
    """The complex formulation of [001] was run at a large l."""


class ComplexFromRestWarning(AccuracyWarning):
    """The complex formulation was started from rest under a motion that lifts the block."""


class LooseToleranceWarning(AccuracyWarning):
    """The nonlinear kernel was run at a tolerance looser than its measured reliable range."""


class IncompleteReferenceWarning(AccuracyWarning):
    """The scipy reference stopped early (its impact cap): the result covers only the start."""


class EquivalentBlockWarning(AccuracyWarning):
    """A structure was run as its equivalent block of [003], which only approximates it."""


class ContactWarning(AccuracyWarning):
    """The block needs more friction than given, or lifts off: it would slide or leave the
    ground, which the rocking model (no sliding, no lift-off) does not describe."""


class SeparationWarning(AccuracyWarning):
    """The binomial (probit) likelihood of a lognormal fragility has no maximum: overturned and
    standing outcomes are (quasi-)completely separated in the intensity (Albert & Anderson
    1984), so beta is not identifiable, or the overturned ones do not lie higher at all."""


class UpliftWarning(AccuracyWarning):
    """A result's uplift level is not the structure's own: a cube written before the design
    carried each structure's uplift acceleration (g lambda, eq. 10 of [003])."""


class UnitsWarning(AccuracyWarning):
    """An input read in the units given lies where real inputs seldom do (a record weaker than
    accelerographs trigger at): the units may be wrong, and every result with them."""
