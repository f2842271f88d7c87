"""Inertia as a function of the Lorentz factor (tumble.lorentz) and the guard rail that states its size (tumble.limits).

No compiled code: closed forms, series and scipy quadrature only.
"""

import math

import numpy as np
import pytest

import tumble
from tumble import limits
from tumble.lorentz import SHAPES, SpinningMatter

C = limits.SPEED_OF_LIGHT
RADIUS = 3.0
# Rim speeds β = ωR/c: the series (β ≤ 0.5), both sides of the switch to the closed forms, and up to γ = 10
BETAS = [1e-4, 0.05, 0.3, 0.5, 0.5000001, 0.7, 0.9, 0.99, math.sqrt(0.99)]


@pytest.mark.parametrize("shape", sorted(SHAPES))
def test_closed_forms_equal_adaptive_quadrature_of_the_definitions(shape):
    # quad at relative tolerance 2e-14 (its floor is 50 eps): 1e-12 leaves room for its own error
    matter = SpinningMatter(shape, mass=2.0, radius=RADIUS)
    for beta in BETAS:
        omega = beta * C / RADIUS
        assert matter.moment(omega) == pytest.approx(matter.quadrature("moment", omega), rel=1e-12, abs=0)
        assert matter.kinetic_energy(omega) == pytest.approx(matter.quadrature("energy", omega), rel=1e-12, abs=0)
        assert matter.angular_momentum(-omega) == pytest.approx(-matter.moment(omega) * omega, rel=1e-15, abs=0)


@pytest.mark.parametrize("shape", sorted(SHAPES))
def test_slow_rotation_gives_the_newtonian_moment_and_energy(shape):
    matter = SpinningMatter(shape, mass=2.0, radius=RADIUS)
    i0 = {"ring": 1.0, "disk": 0.5, "shell": 2.0 / 3.0, "sphere": 0.4}[shape] * 2.0 * RADIUS**2  # textbook
    assert matter.newtonian_moment == pytest.approx(i0, rel=1e-15)
    for omega in (0.0, 1e-3, 1.0):  # rim speeds 0, 1e-11 c, 1e-8 c: relative corrections ≤ 1e-16
        assert matter.moment(omega) == pytest.approx(i0, rel=1e-14, abs=0)
        assert matter.kinetic_energy(omega) == pytest.approx(0.5 * i0 * omega**2, rel=1e-14, abs=0)


def test_the_corrections_start_as_the_fourth_moment_of_the_mass():
    # γ ≈ 1 + β²x²/2 + 3β⁴x⁴/8: I/I₀ − 1 ≈ β² μ₄/(2μ₂) and T/T₀ − 1 ≈ 3β² μ₄/(4μ₂), with μⱼ = ∫ xʲ dm/m
    mu4_over_mu2 = {"ring": 1.0, "disk": (1 / 3) / (1 / 2), "shell": (8 / 15) / (2 / 3), "sphere": (8 / 35) / (2 / 5)}
    beta = 1e-5  # the next terms are β⁴ ≈ 1e-20 relative to these
    for shape, ratio in mu4_over_mu2.items():
        fixes = SpinningMatter(shape, mass=1.0, radius=RADIUS).corrections(beta * C / RADIUS)
        assert fixes["moment"] == pytest.approx(0.5 * ratio * beta**2, rel=1e-9)
        assert fixes["energy"] == pytest.approx(0.75 * ratio * beta**2, rel=1e-9)


def test_the_ring_is_gamma_m_r_squared():
    matter = SpinningMatter("ring", mass=2.0, radius=RADIUS)
    for beta in BETAS:
        omega = beta * C / RADIUS
        v = abs(omega) * RADIUS / C
        gamma = 1.0 / np.sqrt(1.0 - v * v)
        assert matter.moment(omega) == gamma * 2.0 * RADIUS**2
        excess = math.expm1(-0.5 * math.log1p(-v * v))  # γ − 1 without cancellation
        assert matter.kinetic_energy(omega) == pytest.approx(excess * 2.0 * C**2, rel=1e-14)


def test_energy_is_the_work_of_the_momentum():
    # dT = ω dL for dust in rigid rotation (both are ∫ γ³ ω r⊥² dm dω): central differences, step 1e-6 β:
    # truncation ~(1e-6)² γ⁴ ≈ 1e-9 at γ = 7, rounding ~1e-16/1e-6 = 1e-10
    for shape in SHAPES:
        matter = SpinningMatter(shape, mass=1.0, radius=RADIUS)
        for beta in (0.2, 0.8, 0.99):
            omega, h = beta * C / RADIUS, 1e-6 * beta * C / RADIUS
            dT = matter.kinetic_energy(omega + h) - matter.kinetic_energy(omega - h)
            dL = matter.angular_momentum(omega + h) - matter.angular_momentum(omega - h)
            assert dT == pytest.approx(omega * dL, rel=1e-8)


def test_approaching_light_speed():
    # disk and sphere tend to finite limits, I → 4/3 and 3/4 m R², T → 1 and 1/2 m c² (error O(1/γ));
    # the ring and the shell diverge (like γ and like log γ)
    beta = 1.0 - 1e-12
    omega = beta * C / RADIUS
    disk, sphere = SpinningMatter("disk", 1.0, RADIUS), SpinningMatter("sphere", 1.0, RADIUS)
    assert disk.moment(omega) / RADIUS**2 == pytest.approx(4.0 / 3.0, abs=1e-5)
    assert disk.kinetic_energy(omega) / C**2 == pytest.approx(1.0, abs=1e-5)
    assert sphere.moment(omega) / RADIUS**2 == pytest.approx(0.75, abs=1e-5)
    assert sphere.kinetic_energy(omega) / C**2 == pytest.approx(0.5, abs=1e-5)
    assert SpinningMatter("ring", 1.0, RADIUS).moment(omega) / RADIUS**2 > 7e5
    assert SpinningMatter("shell", 1.0, RADIUS).moment(omega) / RADIUS**2 > 6.0


def test_a_rim_at_or_above_light_speed_is_refused():
    matter = SpinningMatter("disk", mass=1.0, radius=RADIUS)
    for omega in (C / RADIUS, -2.0 * C / RADIUS, [0.0, 1.5 * C / RADIUS]):
        with pytest.raises(tumble.ValidationError, match="omega: the rim speed") as err:
            matter.moment(omega)
        assert err.value.field == "omega"
    with pytest.raises(tumble.ValidationError, match="shape: must be one of"):
        SpinningMatter("cube", mass=1.0, radius=1.0)
    with pytest.raises(tumble.ValidationError, match="radius"):
        SpinningMatter("disk", mass=1.0, radius=0.0)


def test_guard_rail_bounds_are_the_ring_and_below_every_other_shape():
    # A thin ring of mass m spinning about its axis: I = diag(½, ½, 1) m R², every particle at v_rms = ωR, so
    # the bounds of tumble.limits are the ring's exact corrections; the other shapes exceed them.
    m = 2.0
    for beta in (1e-3, 0.1, 0.6, 0.95):
        omega = beta * C / RADIUS
        bounds = limits.relativistic_corrections([0.5 * m * RADIUS**2, 0.5 * m * RADIUS**2, m * RADIUS**2],
                                                 [0.0, 0.0, omega], m)
        exact = SpinningMatter("ring", m, RADIUS).corrections(omega)
        assert bounds["speed"] == pytest.approx(beta, rel=1e-15)
        assert bounds["energy"] == pytest.approx(exact["energy"], rel=1e-13)
        assert bounds["momentum"] == pytest.approx(exact["moment"], rel=1e-13)
        for shape, share in (("disk", 0.5), ("sphere", 0.4), ("shell", 2.0 / 3.0)):
            inertia = share * m * RADIUS**2
            b = limits.relativistic_corrections([inertia] * 3, [0.0, 0.0, omega], m)
            fixes = SpinningMatter(shape, m, RADIUS).corrections(omega)
            assert fixes["energy"] >= b["energy"] and fixes["moment"] >= b["momentum"]
    faster = limits.relativistic_corrections([1.0, 1.0, 1.0], [0.0, 0.0, 2.0 * C], 1.0)
    assert faster["energy"] == np.inf and faster["momentum"] == np.inf


def test_the_warning_states_the_size_of_the_neglected_correction():
    sphere = tumble.RigidBody.sphere(mass=2.0, radius=0.1)
    rate = 0.01 * C / (math.sqrt(0.4) * 0.1)  # v_rms = 0.01 c: bounds 7.5e-5 (energy), 5e-5 (momentum)
    with pytest.warns(limits.RigidityWarning, match=r"energy by at least 7\.5e-05 and the angular momentum by "
                                                   r"at least 5e-05"):
        limits.check_rigid_motion(sphere.moments, [0.0, 0.0, rate], sphere.mass)


def test_neutron_star_demo(tmp_path):
    from tumble.viz.lorentz import NEUTRON_STAR, demo_lorentz

    summary = demo_lorentz(tmp_path)
    omega = 2.0 * math.pi / 1.4e-3
    assert summary["rim_speed"] == pytest.approx(omega * 12e3 / C, rel=1e-15)  # 0.1796 c
    sphere = SpinningMatter("sphere", NEUTRON_STAR["mass"], 12e3)
    assert summary["sphere"]["moment"] == pytest.approx(sphere.quadrature("moment", omega) / sphere.newtonian_moment
                                                        - 1.0, rel=1e-10)  # a 0.94 % correction, to 1e-12 of I
    assert (tmp_path / "lorentz.png").stat().st_size > 10_000
