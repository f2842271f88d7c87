"""The environment table along an orbit (tumble.spacecraft.environment_table) against the field's libraries:
the TLE orbit against sgp4, the Sun against skyfield/DE421, eclipse times against a geometric root, the IGRF
against ppigrf at 20 points, the density against pymsis; the J2 drift against the sun-synchronous condition."""

import math
import subprocess
import sys
from datetime import datetime, timedelta, timezone

import numpy as np
import ppigrf
import pymsis
import pytest
from scipy.optimize import brentq
from sgp4.api import Satrec, jday
from skyfield.api import EarthSatellite
from skyfield.constants import AU_M
from skyfield.framelib import itrs
from skyfield.positionlib import Geocentric
from skyfield.sgp4lib import TEME_to_ITRF

import tumble
from tumble.spacecraft import _ephemeris
from tumble.spacecraft.eclipse import EARTH_RADIUS, _overlap_visible, shadow_fraction
from tumble.spacecraft.environment_table import Environment, SpaceWeather
from tumble.spacecraft.igrf import igrf_field
from tumble.spacecraft.orbit import Orbit
from tumble.spacecraft.tle import TLE

# The ISS elements of sgp4's own documentation.
ISS = ("1 25544U 98067A   19343.69339541  .00001764  00000-0  38792-4 0  9991",
       "2 25544  51.6439 211.2001 0007417  17.6667  85.6398 15.50103472202482")
EQUINOX = datetime(2026, 3, 20, 12, 0, tzinfo=timezone.utc)

# IGRF synthesis against ppigrf: both sum the same degree-13 series in float64 (measured worst 3e-15).
IGRF_RTOL = 1e-9
# The Sun and the Moon seen from the craft, both by skyfield from the same DE421: rounding of 1 au in float64
# and of the craft's offset in au.
SUN_DIRECTION_TOL = 1e-12
MOON_DIRECTION_TOL = 1e-12


@pytest.fixture(scope="module")
def iss_env():
    return Environment.sample(TLE(*ISS), duration=600.0, step=10.0)


# -- IGRF-14 ----------------------------------------------------------------------------------------------


def test_igrf_matches_ppigrf_at_20_points():
    rng = np.random.default_rng(14)
    radius = rng.uniform(6360e3, 42000e3, 20)
    colat = np.concatenate([[1e-7, 0.5, 90.0, 179.5], rng.uniform(0.0, 180.0, 16)])
    lon = rng.uniform(-180.0, 180.0, 20)
    first = datetime(1900, 1, 1)
    dates = [first + timedelta(days=float(d)) for d in rng.uniform(0.0, (datetime(2030, 1, 1) - first).days, 20)]
    th, ph = np.radians(colat), np.radians(lon)
    r_itrs = radius[:, None] * np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], axis=1)
    ours = igrf_field(r_itrs, dates)
    for k in range(20):
        br, bt, bp = (c.item() * 1e-9 for c in ppigrf.igrf_gc(radius[k] / 1e3, colat[k], lon[k], dates[k]))
        theirs = (br * np.array([np.sin(th[k]) * np.cos(ph[k]), np.sin(th[k]) * np.sin(ph[k]), np.cos(th[k])])
                  + bt * np.array([np.cos(th[k]) * np.cos(ph[k]), np.cos(th[k]) * np.sin(ph[k]), -np.sin(th[k])])
                  + bp * np.array([-np.sin(ph[k]), np.cos(ph[k]), 0.0]))
        assert np.linalg.norm(ours[k] - theirs) <= IGRF_RTOL * np.linalg.norm(theirs)


def test_igrf_is_finite_on_the_polar_axis_and_continuous_to_it():
    when = datetime(2025, 6, 1)
    on_axis = igrf_field([0.0, 0.0, 7000e3], when)
    near = igrf_field([1e-3, 0.0, 7000e3], when)
    # 1 mm off the axis the field differs by its gradient, ~|B|/r × 1 mm = 1.4e-10 of |B|
    assert np.all(np.isfinite(on_axis)) and np.linalg.norm(on_axis - near) < 1e-9 * np.linalg.norm(on_axis)


# -- orbits -----------------------------------------------------------------------------------------------


def test_tle_state_is_sgp4s_own(iss_env):
    sat = Satrec.twoline2rv(*ISS)
    jd, fr = jday(2019, 12, 9, 16, 38, 29.363424)         # the TLE's epoch, 19343.69339541
    for k in (0, 30, 60):
        _, r, v = sat.sgp4(jd, fr + iss_env.t[k] / 86400.0)
        r_teme, v_teme = TLE(*ISS).state_teme(iss_env.epoch, iss_env.t[k:k + 1])
        assert np.abs(r_teme[0] - 1e3 * np.array(r)).max() < 1e-3      # m: the datetime epoch is exact here
        assert np.abs(v_teme[0] - 1e3 * np.array(v)).max() < 1e-6


def test_a_tle_and_its_environment_pickle(iss_env):
    import pickle

    again = pickle.loads(pickle.dumps(iss_env))
    assert again.orbit == iss_env.orbit and np.array_equal(again.data, iss_env.data)
    r, _ = again.orbit.state_teme(again.epoch, again.t[:2])
    assert np.array_equal(r, TLE(*ISS).state_teme(iss_env.epoch, iss_env.t[:2])[0])


def test_tle_gcrs_matches_skyfields_satellite_and_the_classic_teme_to_itrf_chain(iss_env):
    ts, _ = _ephemeris.loaded()
    time = _ephemeris.times(iss_env.epoch, iss_env.t)
    sat = EarthSatellite(*ISS, ts=ts)
    assert np.abs(sat.at(time).position.m.T - iss_env.position).max() < 1e-3       # m
    assert np.abs(sat.at(time).velocity.m_per_s.T - iss_env.velocity).max() < 1e-6
    # GCRS -> ITRS (IAU 2006/2000A, polar motion) against TEME -> PEF by GMST 1982 (AIAA 2006-6753): they
    # differ by the polar motion (0.3", 10 m at 7000 km) and the rotation conventions (milliarcseconds)
    r_teme, _ = TLE(*ISS).state_teme(iss_env.epoch, iss_env.t)
    r_pef, _ = TEME_to_ITRF(time.whole, r_teme.T, np.zeros_like(r_teme.T), 0.0, 0.0, time.ut1_fraction)
    r_itrs = np.einsum("kij,kj->ki", _ephemeris.rotation_itrs_gcrs(time), iss_env.position)
    assert np.linalg.norm(r_itrs - r_pef.T, axis=1).max() < 30.0


def test_j2_drift_is_the_sun_synchronous_rate_and_the_velocity_is_the_derivative():
    orbit = Orbit.circular(700e3, np.radians(98.19))        # the textbook sun-synchronous orbit at 700 km
    raan_rate, _, _ = orbit.j2_rates()
    assert raan_rate == pytest.approx(2 * math.pi / (365.2422 * 86400.0), rel=2e-3)
    elliptic = Orbit(7.5e6, 0.05, 1.1, 0.3, 0.7, 0.2)
    t, h = np.array([1000.0, 40000.0]), 0.01
    r, v = elliptic.state(t, j2=True)
    r_plus, _ = elliptic.state(t + h, j2=True)
    r_minus, _ = elliptic.state(t - h, j2=True)
    assert np.abs((r_plus - r_minus) / (2 * h) - v).max() < 1e-5           # m/s: O(h²) of the difference
    assert np.abs(r - elliptic.state(t)[0]).max() > 1e3                      # the drift is there


# -- the Sun, the Moon and the shadow -----------------------------------------------------------------------


def test_sun_direction_and_distance_match_skyfield_seen_from_the_craft(iss_env):
    ts, planets = _ephemeris.loaded()
    time = _ephemeris.times(iss_env.epoch, iss_env.t)
    seen = (planets["earth"] + EarthSatellite(*ISS, ts=ts)).at(time).observe(planets["sun"]).position.m.T
    distance = np.linalg.norm(seen, axis=1)
    angle = np.linalg.norm(np.cross(seen / distance[:, None], iss_env.sun_direction), axis=1)
    assert angle.max() < SUN_DIRECTION_TOL
    assert np.abs(iss_env.sun_distance / distance - 1.0).max() < 1e-9
    moon = (planets["earth"] + EarthSatellite(*ISS, ts=ts)).at(time).observe(planets["moon"]).position.m.T
    moon /= np.linalg.norm(moon, axis=1)[:, None]
    assert np.linalg.norm(np.cross(moon, iss_env.moon_direction), axis=1).max() < MOON_DIRECTION_TOL


def _geometric_cylinder_crossings(orbit, epoch, t_end):
    """Times where |r⊥| = R_E on the night side, by brentq on Orbit.state and skyfield's Sun directly."""
    ts, planets = _ephemeris.loaded()
    t0 = ts.from_datetime(epoch)

    def margin(t):
        r = orbit.state(t)[0]
        sun = planets["earth"].at(ts.tt_jd(t0.whole, t0.tt_fraction + t / 86400.0)).observe(planets["sun"])
        s = sun.position.m - r
        s /= np.linalg.norm(s)
        along = r @ s
        return math.sqrt(r @ r - along**2) - EARTH_RADIUS if along < 0 else 1e6

    grid = np.arange(0.0, t_end, 20.0)
    values = np.array([margin(t) for t in grid])
    return [brentq(margin, grid[k], grid[k + 1], xtol=1e-6)
            for k in np.flatnonzero(np.sign(values[:-1]) != np.sign(values[1:]))]


def test_cylindrical_eclipse_entry_and_exit_match_the_geometric_roots():
    orbit = Orbit.circular(500e3, 0.0)
    env = Environment.sample(orbit, EQUINOX, duration=orbit.period, step=1.0, shadow="cylindrical")
    jumps = np.flatnonzero(np.diff(env.shadow) != 0.0)
    roots = _geometric_cylinder_crossings(orbit, EQUINOX, env.t[-1])
    assert len(jumps) == len(roots) == 2
    for k, root in zip(jumps, roots, strict=True):
        assert env.t[k] <= root <= env.t[k + 1]                 # each crossing inside its 1 s sample step


def test_conical_shadow_umbra_inside_cylinder_inside_penumbra():
    orbit = Orbit.circular(500e3, 0.0)
    cyl = Environment.sample(orbit, EQUINOX, duration=orbit.period, step=1.0, shadow="cylindrical")
    r_sun = cyl.position + cyl.sun_direction * cyl.sun_distance[:, None]
    nu = shadow_fraction(cyl.position, r_sun, "conical")
    umbra, dark, lit = nu == 0.0, cyl.shadow == 0.0, nu == 1.0
    assert umbra.sum() < dark.sum() < (~lit).sum()
    assert np.all(dark[umbra]) and np.all(~lit[dark])
    # the penumbra lasts about (apparent solar diameter / orbit rate) / cos(angle of the limb): ~9 s here
    assert 6 <= (~lit & ~umbra).sum() / 2 <= 12


def test_penumbra_fraction_matches_quadrature_of_the_two_discs():
    a, b = 4.65e-3, 1.16                          # the Sun's and the Earth's apparent radii at 500 km, rad
    u, w = np.meshgrid(np.linspace(-a, a, 2001), np.linspace(-a, a, 2001))
    on_sun = u**2 + w**2 <= a * a
    for c in (b - 0.8 * a, b - 0.1 * a, b + 0.5 * a, b + 0.95 * a):
        visible = on_sun & ((u + c) ** 2 + w**2 > b * b)        # the Earth's centre at (-c, 0)
        assert _overlap_visible(np.array([a]), np.array([b]), np.array([c]))[0] == pytest.approx(
            visible.sum() / on_sun.sum(), abs=2e-3)              # the grid's resolution of the disc


def test_annular_shadow_is_one_minus_the_ratio_of_areas():
    assert _overlap_visible(np.array([2e-3]), np.array([1e-3]), np.array([0.5e-3]))[0] == pytest.approx(0.75)


# -- the field, the atmosphere -----------------------------------------------------------------------------


def test_field_column_is_igrf_in_the_itrs_turned_to_gcrs(iss_env):
    time = _ephemeris.times(iss_env.epoch, iss_env.t)
    rot = np.moveaxis(itrs.rotation_at(time), -1, 0)
    r_itrs = np.einsum("kij,kj->ki", rot, iss_env.position)
    b_itrs = np.einsum("kij,kj->ki", rot, iss_env.magnetic_field)
    for k in (0, 25, 60):
        x, y, z = r_itrs[k] / 1e3
        rad = math.sqrt(x * x + y * y + z * z)
        colat, lon = math.degrees(math.acos(z / rad)), math.degrees(math.atan2(y, x))
        when = iss_env.epoch.replace(tzinfo=None) + timedelta(seconds=float(iss_env.t[k]))
        br = ppigrf.igrf_gc(rad, colat, lon, when)[0].item() * 1e-9
        assert b_itrs[k] @ r_itrs[k] / np.linalg.norm(r_itrs[k]) == pytest.approx(br, rel=1e-9)


def test_air_velocity_is_the_velocity_in_the_earth_fixed_frame(iss_env):
    time = _ephemeris.times(iss_env.epoch, iss_env.t)
    position = Geocentric(iss_env.position.T / AU_M, iss_env.velocity.T / AU_M * 86400.0, t=time)
    _, v_itrs = position.frame_xyz_and_velocity(itrs)
    assert np.abs(np.linalg.norm(iss_env.velocity_air, axis=1) / np.linalg.norm(v_itrs.m_per_s.T, axis=1)
                  - 1.0).max() < 1e-6


def test_density_is_nrlmsis_at_the_geodetic_point(iss_env):
    time = _ephemeris.times(iss_env.epoch, iss_env.t)
    rot = np.moveaxis(itrs.rotation_at(time), -1, 0)
    r_itrs = np.einsum("kij,kj->ki", rot, iss_env.position) / 1e3
    radius = np.linalg.norm(r_itrs, axis=1)
    colat = np.degrees(np.arccos(r_itrs[:, 2] / radius))
    lat, height, _, _ = ppigrf.ppigrf.geoc2geod(colat, radius, colat, colat)   # ppigrf's geodetic conversion
    lon = np.degrees(np.arctan2(r_itrs[:, 1], r_itrs[:, 0]))
    dates = np.array([iss_env.epoch.replace(tzinfo=None) + timedelta(seconds=float(s)) for s in iss_env.t],
                     dtype="datetime64[us]")
    n = len(dates)
    rho = pymsis.calculate(dates, lon, lat, height, np.full(n, 150.0), np.full(n, 150.0), np.full((n, 7), 15.0),
                           version=2.1)[:, 0]
    assert np.abs(iss_env.density / rho - 1.0).max() < 1e-5      # pymsis reads its inputs as float32
    assert 1e-12 < iss_env.density.min() and iss_env.density.max() < 1e-10   # 400-420 km, moderate activity


# -- bad input ---------------------------------------------------------------------------------------------


def _bad_checksum(line):
    return line[:68] + str((int(line[68]) + 1) % 10)


@pytest.mark.parametrize(("lines", "message"), [
    ((_bad_checksum(ISS[0]), ISS[1]), r"^tle\.line1: checksum must be 1 "),
    ((ISS[0], _bad_checksum(ISS[1])), r"^tle\.line2: checksum must be 2 "),
    ((ISS[0][:60], ISS[1]), r"^tle\.line1: must be 69 characters long, got 60"),
    ((ISS[1], ISS[0]), r"^tle\.line1: must start with its line number 1"),
])
def test_a_bad_tle_is_refused_naming_the_line_and_the_rule(lines, message):
    with pytest.raises(tumble.ValidationError, match=message):
        TLE(*lines)


@pytest.mark.parametrize(("epoch", "message"), [
    (datetime(2060, 1, 1), r"^epoch: the run must lie within the ephemeris DE421 \(1899-07-2\d to 2053-10-"),
    (datetime(2053, 10, 5), r"^epoch: the run must lie within the ephemeris DE421"),      # the run ends past it
    (datetime(2031, 1, 1), r"^epoch: must be within IGRF-14 \(1900-01-01 to 2030-01-01\)"),
    ("2026-03-20", r"^epoch: must be a UTC datetime"),
])
def test_an_epoch_outside_the_data_is_refused(epoch, message):
    with pytest.raises(tumble.ValidationError, match=message):
        Environment.sample(Orbit.circular(500e3), epoch, duration=10 * 86400.0, step=60.0)


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"shadow": "round"}, r"^shadow: must be one of conical, cylindrical"),
    ({"step": 0.0}, r"^step: must be a finite number > 0"),
    ({"duration": -1.0}, r"^duration: must be a finite number > 0"),
    ({"space_weather": "quiet"}, r"^space_weather: must be a SpaceWeather"),
])
def test_bad_sampling_options_are_refused(kwargs, message):
    with pytest.raises(tumble.ValidationError, match=message):
        Environment.sample(Orbit.circular(500e3), EQUINOX, **{"duration": 60.0, **kwargs})


def test_bad_space_weather_is_refused():
    with pytest.raises(tumble.ValidationError, match=r"^space_weather\.ap: must be in \[0, 400\], got 500"):
        SpaceWeather(ap=500.0)
    with pytest.raises(tumble.ValidationError, match=r"^space_weather\.f107: must be a finite number > 0"):
        SpaceWeather(f107=0.0)


def test_import_tumble_imports_none_of_the_environment_libraries():
    code = ("import sys, tumble, tumble.spacecraft, tumble.spacecraft.environment_table; "
            "print(sorted(m for m in ('sgp4', 'skyfield', 'pymsis', 'ppigrf', 'skyfield_data') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_nothing_reaches_the_network():
    # a fresh process with every socket refused: the ephemeris, the Earth-orientation data, the IGRF
    # coefficients and NRLMSIS's parameters all load from the installed packages
    code = (
        "import socket\n"
        "def refuse(*args, **kwargs):\n"
        "    raise OSError('network access refused by the test')\n"
        "socket.socket.connect = refuse\n"
        "socket.create_connection = refuse\n"
        "from tumble.spacecraft import TLE, Environment\n"
        f"env = Environment.sample(TLE({ISS[0]!r}, {ISS[1]!r}), duration=60.0, step=10.0)\n"
        "print(env.density.min() > 0.0, abs(env.magnetic_field).max() > 0.0)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["True", "True"]
