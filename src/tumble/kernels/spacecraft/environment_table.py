"""The columns of the environment table (:class:`tumble.spacecraft.environment_table.Environment`).

One row per sample time; inertial = GCRS axes, SI units. The index of each
column's first component is a module constant, so that compiled code names
what it reads.
"""

#: position of the craft r, m (3)
POSITION = 0
#: velocity of the craft v, m/s (3)
VELOCITY = 3
#: unit vector from the craft to the Sun ŝ (3)
SUN_DIRECTION = 6
#: distance from the craft to the Sun |s|, m (1)
SUN_DISTANCE = 9
#: fraction of the solar disc seen, ν ∈ [0, 1] (1)
SHADOW = 10
#: geomagnetic field B, T (3)
MAGNETIC_FIELD = 11
#: atmospheric mass density ρ, kg/m³ (1)
DENSITY = 14
#: velocity relative to the co-rotating atmosphere v − ω⊕ × r, m/s (3)
VELOCITY_AIR = 15
#: unit vector from the craft to the Moon (3)
MOON_DIRECTION = 18
#: number of columns
WIDTH = 21

#: name → (first column, number of components)
COLUMNS = {
    "position": (POSITION, 3),
    "velocity": (VELOCITY, 3),
    "sun_direction": (SUN_DIRECTION, 3),
    "sun_distance": (SUN_DISTANCE, 1),
    "shadow": (SHADOW, 1),
    "magnetic_field": (MAGNETIC_FIELD, 3),
    "density": (DENSITY, 1),
    "velocity_air": (VELOCITY_AIR, 3),
    "moon_direction": (MOON_DIRECTION, 3),
}
