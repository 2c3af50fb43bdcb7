"""Physical constants used throughout rockstudy (SI units).

Two values of g, on purpose:

- :data:`G` is the gravity of the physics: it sets the frequency parameter p = sqrt(3 g / 4 R)
  (eq. (2.2) of [000]), the uplift acceleration g tan(alpha), Arias intensity's pi / (2 g), and
  every dimensionless group. It is 9.81 m/s^2, the value of the papers' worked examples; it is
  stored in every study cube as the attribute ``gravity``.
- :data:`STANDARD_GRAVITY` is the *unit* g: 9.80665 m/s^2 exactly (the CGPM's standard
  gravity). A record "in g" (PEER ``.AT2`` files, ``units="g"``) is converted to m/s^2 with it,
  as PEER's processing does, and accelerations are written back in g with it; it is stored in
  every study cube as ``record_g_unit``.

The two differ by 3.4e-4 (relative). Keeping the physics at 9.81 keeps every kernel output as
it was; converting units with 9.80665 keeps a PEER record's own velocity and displacement.
"""

__all__ = ["FALL_ROTATION", "G", "STANDARD_GRAVITY"]

#: Gravity of the physics [m/s^2]: p = sqrt(3 g / 4 R), uplift at g tan(alpha), Arias' pi / 2g.
G = 9.81

#: Standard gravity g_n [m/s^2], exact by definition: the unit "g" of records in g.
STANDARD_GRAVITY = 9.80665

#: Rotation at which an overturning block lies on its side and the simulation stops [rad].
FALL_ROTATION = 1.5707963267948966
