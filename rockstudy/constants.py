"""Physical constants used throughout rockstudy (SI units)."""

#: Standard acceleration of gravity [m/s^2].
G = 9.81

#: Rotation at which an overturning block lies on its side and the simulation stops [rad].
FALL_ROTATION = 1.5707963267948966
