"""The demonstrations, as the one table the ``tumble demo`` command reads.

Each demo is a function ``demo_xxx(out_dir, **options) -> dict`` of :mod:`tumble.viz` (the figures and demos of
a domain: ``tumble.viz.flexible``, ``tumble.viz.passive``, ...) that writes its files atomically into an
existing directory and returns its numbers. A row of :data:`DEMOS` (its key the demo's name) says what it shows
(the first line of its help), names its function (``"module:function"``, imported only when the demo runs),
its options as data (:class:`Option`), the files it writes, and turns the returned numbers into printed rows.
:mod:`tumble.cli.demo` makes one ``tumble demo NAME [-o DIRECTORY] [options]`` command per row; this module
imports nothing of the CLI.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from tumble.viz._rows import summary

__all__ = ["DEMOS", "Demo", "Option", "resolve"]

Rows = Callable[[dict], list[tuple[str, str]]]


def resolve(target: str) -> Callable[..., Any]:
    """The function that ``"module:function"`` names, its module imported now."""
    module, function = target.split(":")
    return getattr(importlib.import_module(module), function)


@dataclass(frozen=True)
class Option:
    """An option ``FLAG VALUE`` of a demo, passed to its function as the keyword argument ``keyword``.

    flag    : the command-line spelling, e.g. ``"--duration"``
    keyword : the keyword argument of the demo's function that it sets
    type    : ``float`` or ``int``
    default : the value when the option is not given (the function's own default)
    help    : one line for ``--help``, with the unit
    check   : ``"module:function"``, a function ``(value, name) -> value`` that refuses a bad value with a
              :class:`~tumble.ValidationError` naming ``name`` (the CLI passes the flag), before the demo runs
    """

    flag: str
    keyword: str
    type: type
    default: float | int
    help: str
    check: str = "tumble._validate:require_positive"


@dataclass(frozen=True)
class Demo:
    """One ``tumble demo NAME`` command.

    target   : ``"module:function"``, a function ``(out_dir, **options) -> dict`` that writes ``files`` in
               ``out_dir``
    help     : the command's help; its first line says what the demo shows (``tumble demo --list``)
    rows     : the printed rows ``(label, text)`` of the returned dict (the CLI adds the files written)
    files    : the names of the files it writes in ``out_dir`` (checked before it runs, printed after)
    options  : its options beside ``-o DIRECTORY``
    progress : whether the function takes ``progress=`` (a callback ``(done, total)``: the CLI draws a
               progress bar on a terminal, off with ``--quiet``)
    """

    target: str
    help: str
    rows: Rows
    files: tuple[str, ...]
    options: tuple[Option, ...] = ()
    progress: bool = False

    @property
    def shows(self) -> str:
        """What the demo shows: the first line of its help."""
        return self.help.strip().splitlines()[0]


def _racket_rows(s: dict) -> list[tuple[str, str]]:
    mean = (f", mean time between flips {s['mean_flip_interval_s']:.6g} s"
            if s["mean_flip_interval_s"] is not None else "")
    return [*summary(s["trajectory"]), ("flips", f"{s['flips']} in {s['duration_s']:g} s{mean}"),
            ("predicted", f"time between flips 2K/lambda = {s['predicted_flip_interval_s']:.6g} s (exact solution)")]


_DURATION = "Simulated time, s."

DEMOS: dict[str, Demo] = {
    "racket": Demo(
        "tumble.viz.racket:demo_racket",
        """Tennis-racket (Dzhanibekov) effect: a T-handle spun about its intermediate axis flips over and over.

        The default RigidBody.t_handle() starts at 10 rad/s about its intermediate principal axis
        with 1e-3 rad/s about the other two, integrated by dop853 at rtol = atol = 1e-12. A flip
        is a sign change of the intermediate-axis rate; the command prints their number, the
        mean time between them, and the time between flips predicted by the exact (elliptic)
        solution, 2K(m)/lambda. Writes racket.nc (the run), racket.png (the rates, flips marked)
        and racket.html (the offline 3-D viewer) in the directory.
        """,
        _racket_rows,
        ("racket.nc", "racket.png", "racket.html"),
        (Option("--duration", "duration", float, 20.0, _DURATION, "tumble.viz.racket:check_duration"),),
        progress=True,
    ),
    "polhode": Demo(
        "tumble.viz.polhode:demo_polhode",
        """Poinsot's construction: polhodes on the energy ellipsoid and the herpolhode of a T-handle.

        RigidBody.t_handle() spinning at 10 rad/s about its intermediate principal axis and 1 rad/s
        about each of the other two. The figure (tumble.viz.polhode.polhode_figure) shows the energy
        ellipsoid with a family of polhodes, the separatrix and this motion's polhode, and the
        herpolhode on the invariable plane; the command prints the stability of the axes and the
        predicted times. Writes polhode.png and polhode.html (the 3-D viewer of one polhode period:
        the T-handle turning, omega and L, and its polhode on the energy ellipsoid) in the directory.
        """,
        lambda s: [
            ("body", "T-handle, principal moments " + ", ".join(f"{m:.4g}" for m in s["moments"]) + " kg m^2"),
            ("axes", ", ".join(f"{i + 1}: {kind}" for i, kind in enumerate(s["axis_stability"]))),
            ("omega", "[" + ", ".join(f"{w:g}" for w in s["omega_principal"]) + "] rad/s (principal axes), "
                      f"regime {s['regime']!r}"),
            ("timing", f"flips every 2K/lambda = {s['flip_interval_s']:.6g} s, "
                       f"polhode period 4K/lambda = {s['polhode_period_s']:.6g} s"),
        ],
        ("polhode.png", "polhode.html"),
    ),
    "top": Demo(
        "tumble.viz.top:demo_top",
        """Heavy symmetric top: simulation (gravity torque on a pivot) against the exact theory.

        A spinning top released at 60 deg from the vertical nutates between two angles while it
        precesses (docs/heavy_top.md). Prints the nutation bounds, the nutation period and the mean
        precession rate, exact and measured. Writes top.nc, top.png and top.html (the 3-D viewer of
        the run) in the directory.
        """,
        lambda s: [
            ("nutation", f"theta from {s['theta_min_deg']:.6g} to {s['theta_max_deg']:.6g} deg (exact), "
                         f"{s['theta_min_deg_measured']:.6g} to {s['theta_max_deg_measured']:.6g} deg (simulated)"),
            ("period", f"{s['nutation_period_s']:.6g} s (exact), {s['nutation_period_s_measured']:.6g} s (simulated)"),
            ("rate", f"mean precession rate {s['mean_precession_rate']:.6g} rad/s (exact), "
                     f"{s['mean_precession_rate_measured']:.6g} rad/s (simulated)"),
            ("spin", f"{s['spin']:.6g} rad/s (critical spin {s['critical_spin']:.6g} rad/s: "
                     "the upright top is stable above it)"),
        ],
        ("top.nc", "top.png", "top.html"),
        (Option("--duration", "duration", float, 1.5, _DURATION),),
    ),
    "diver": Demo(
        "tumble.viz.diver:demo_diver",
        """A diver's twisting somersaults: a segment model (de Leva 1996) whose arms move in flight.

        Runs the three experiments of docs/diver.md: (a) a layout somersault that acquires twist
        when one arm drops; (b) the rule of thumb twists/somersault = sin(tilt) (I_s/I_l - 1)
        against simulation over tilts of 2-30 deg; (c) a forward 1.5-somersault dive with twists.
        Writes diver_twisting_somersault.png, diver_twist_rule.png, diver_513xd.png and
        diver_513xd.nc in the directory.
        """,
        lambda s: [
            ("(a)", f"{s['twisting_somersault_twists']:.2f} twists in {s['twisting_somersault_somersaults']:.2f} "
                    "somersaults after the left arm drops"),
            ("(b)", f"rule of thumb within {s['rule_max_relative_error_10_30_deg']:.1%} of the simulation "
                    "for tilts of 10-30 deg"),
            ("(c)", f"{abs(s['dive_somersaults']):.2f} somersaults, {abs(s['dive_twists']):.2f} twists, "
                    f"final tilt {s['dive_final_tilt_deg']:.1f} deg"),
            ("|L|", "largest relative drift "
                    f"{max(s['dive_momentum_drift'], s['twisting_somersault_momentum_drift']):.1e} "
                    "(torque-free flight: L is conserved)"),
        ],
        ("diver_twisting_somersault.png", "diver_twist_rule.png", "diver_513xd.png", "diver_513xd.nc", "diver_513xd.html"),
    ),
    "flexible": Demo(
        "tumble.viz.flexible:demo_flexible",
        """A 30 deg rest-to-rest slew of a spacecraft with two flexible panel modes (0.2 and 1.1 Hz).

        Bang-bang torque over 40 s, flexible hub against the rigid body (docs/flexible.md): the
        panels keep vibrating after the manoeuvre and the hub jitters. Writes flexible.nc and
        flexible.png in the directory.
        """,
        lambda s: [
            ("torque", f"bang-bang, peak {s['peak_torque']:.4g} N m"),
            ("modes", "residual amplitude " + ", ".join(f"{a:.3g}" for a in s["residual_modal_amplitude"])
                      + " kg^0.5 m after the slew"),
            ("jitter", f"{s['jitter_peak_arcsec']:.4g} arcsec peak, {s['jitter_rms_arcsec']:.4g} arcsec RMS, rate "
                       f"{s['rate_jitter_peak_arcsec_per_s']:.4g} arcsec/s peak (rigid body: "
                       f"{s['rigid_pointing_error_arcsec']:.2g} arcsec)"),
        ],
        ("flexible.nc", "flexible.png", "flexible.html"),
    ),
    "slosh": Demo(
        "tumble.viz.slosh:demo_slosh",
        """Fuel slosh turns a minor-axis spinner into a flat spin (pendulum analogue, docs/slosh.md).

        The nutation angle grows exponentially at the rate of the linearised steady spin while the
        sloshing fuel dissipates energy at constant |H|, until the spacecraft spins about its major
        axis. Writes slosh.nc and slosh.png in the directory.
        """,
        lambda s: [
            ("nutation", f"{s['nutation_initial_deg']:.3g} deg -> {s['nutation_final_deg']:.4g} deg"),
            ("growth", f"time constant {s['growth_time_constant_s']:.4g} s (simulation), "
                       f"{s['growth_time_constant_linear_s']:.4g} s (linearised steady spin)"),
            ("energy", f"{s['energy_change']:+.1%}, final {s['energy_final']:.7g} J vs flat spin "
                       f"{s['energy_flat_spin']:.7g} J, monotonic: {s['energy_monotonic']}"),
            ("|H|", f"largest relative drift {s['momentum_norm_drift']:.1e}"),
        ],
        ("slosh.nc", "slosh.png", "slosh.html"),
    ),
    "gyro": Demo(
        "tumble.viz.ins:demo_gyroscope",
        """A mechanical gyroscope: precession under a torque, nutation, and drift from imbalance and friction.

        A rotor on a pivot simulated with Euler's equations (docs/ins.md): precession rate
        torque/(I_s w_s) and nutation period against theory. Writes ins_gyro_precession.png and
        ins_gyro_drift.png in the directory.
        """,
        lambda s: [
            ("precession", f"{s['precession_rate_measured']:.9g} rad/s (simulated), "
                           f"{s['precession_rate']:.9g} rad/s (torque/(I_s w_s))"),
            ("nutation", f"period {s['nutation_period_s_measured']:.9g} s (simulated), "
                         f"{s['nutation_period_s_exact']:.9g} s (exact heavy top), "
                         f"{s['nutation_period_s']:.9g} s (2 pi I_t/(I_s w_s))"),
            ("drift", f"against the laws: imbalance {s['imbalance_drift_error_rad']:.2g} rad, spin drag "
                      f"{s['spin_drag_drift_error_rad']:.2g} rad, pivot friction {s['pivot_tilt_error_rad']:.2g} rad"),
        ],
        ("ins_gyro_precession.png", "ins_gyro_precession.html", "ins_gyro_drift.png"),
    ),
    "coning": Demo(
        "tumble.viz.ins:demo_coning",
        """The classic coning test of strapdown attitude algorithms (alpha = 0.01 rad, Omega = 2 pi rad/s).

        Drift rate about the cone axis of the uncompensated, one-, two- and three-sample
        algorithms against their laws (docs/ins.md): 1/2 sin^2(alpha) Omega (1 - sin(Omega T)/(Omega T))
        uncompensated, alpha^2 Omega (Omega T)^4/60 one-sample, alpha^2 Omega (Omega T)^4/960 two-sample and
        alpha^2 Omega (Omega T)^6/204120 three-sample. Writes ins_coning.png in the directory.
        """,
        lambda s: [(algorithm, f"measured drift within {s[algorithm]['max_relative_deviation']:.1%} of its law")
                   for algorithm in ("none", "one-sample", "two-sample", "three-sample")],
        ("ins_coning.png", "ins_coning.html"),
    ),
    "ins": Demo(
        "tumble.viz.ins:demo_ins",
        """End to end: a tumbling body, a gyro with errors, strapdown integration, attitude error.

        The exact torque-free motion is sampled by a 200 Hz gyro (error-free, angle random walk only,
        all error terms) and integrated back with the three-sample algorithm for 60 s; the same gyro
        at rest gives an Allan deviation from which N and B are recovered (docs/ins.md). Writes
        ins_error.png and ins_allan.png in the directory.
        """,
        lambda s: [
            *[(name, f"attitude error after {s['duration_s']:g} s: {s[name]['final_rad']:.2g} rad")
              for name in ("error-free", "angle random walk", "all error terms")],
            ("ARW", f"prediction N sqrt(3t) = {s['arw_prediction_rad']:.2g} rad"),
            ("Allan", f"N {s['white_noise']:.3g} -> recovered "
                      + ", ".join(f"{v:.3g}" for v in s["white_noise_recovered"])
                      + f"; B {s['bias_instability']:.3g} -> recovered "
                      + ", ".join(f"{v:.3g}" for v in s["bias_instability_recovered"])),
        ],
        ("ins_error.png", "ins_truth.html", "ins_allan.png"),
    ),
    "explorer1": Demo(
        "tumble.viz.passive:demo_explorer1",
        """Explorer 1 (1958): a spin about the minor axis decays into a flat spin about the major axis.

        The satellite (750 rpm about its long, minor axis) dissipates energy in a spherical viscous
        damper standing in for its whip antennas; the nutation angle grows to 90 deg at constant |L|
        with the energy-sink time constant (docs/passive_stability.md). Writes explorer1.nc and
        explorer1.png in the directory.
        """,
        lambda s: [
            ("time", f"constant {s['time_constant_s']:.4g} s (simulation), {s['time_constant_estimate_s']:.4g} s "
                     "(energy-sink estimate)"),
            ("nutation", f"final {s['final_nutation_deg']:.4f} deg: a flat spin about the major axis"),
            ("energy", f"{s['energy_initial_J']:.4g} J -> {s['energy_final_J']:.4g} J, "
                       + ("falling at every sample" if s["max_energy_increase"] < 0.0 else
                          f"rising by up to {s['max_energy_increase']:.1e} (relative) between samples")),
            ("|L|", f"largest relative drift {s['momentum_drift']:.1e} (magnitude), {s['momentum_vector_drift']:.1e} "
                    "(inertial vector), hub and damper together"),
        ],
        ("explorer1.nc", "explorer1.png", "explorer1.html"),
    ),
    "gravity-gradient": Demo(
        "tumble.viz.passive:demo_gravity_gradient",
        """A gravity-gradient-stabilised satellite librating about the local-vertical frame (LVLH).

        Classifies the spacecraft in the (k_R, k_Y) plane (Lagrange and DeBra-Delp regions),
        simulates its libration on a circular orbit and draws both (docs/passive_stability.md).
        """,
        lambda s: [
            ("region", f"{s['region']} (k_R = {s['k_roll']:.4g}, k_Y = {s['k_yaw']:.4g})"),
            ("frequency", f"pitch {s['pitch_frequency']:.5g} n, roll/yaw "
                          + ", ".join(f"{f:.5g}" for f in s["roll_yaw_frequencies"])
                          + f" n (orbit period {s['orbit_period_s']:.6g} s)"),
            ("libration", f"largest roll/pitch/yaw angle {s['max_angle_deg']:.3g} deg"),
        ],
        ("gravity_gradient.nc", "gravity_gradient.png", "passive_gg_regions.png", "gravity_gradient.html"),
    ),
    "budget": Demo(
        "tumble.viz.budget:demo_budget",
        """A pointing and momentum budget: an Earth-pointing LEO smallsat with four wheels over a day.

        The disturbance torques by source (gravity gradient, solar pressure and drag on its six faces,
        a residual dipole in IGRF-14) along a 500 km dawn-dusk sun-synchronous orbit, the momentum the
        wheels must store against the closed-form estimates of SMAD (Larson & Wertz 1999, section 11.1),
        eclipse seasons over a year, and a Monte-Carlo sweep over facet coefficients and centre-of-mass
        offset (docs/spacecraft_environment.md). About a minute (--hours 1 --samples 2: seconds). Writes
        budget.png in the directory.
        """,
        lambda s: [
            *[(source.replace("_", " "), f"peak {s['peak_torque'][source]:.3g} N m (SMAD "
                                         f"{s['estimate_torque'][source]:.3g}), momentum "
                                         f"{s['peak_momentum'][source]:.3g} N m s (SMAD "
                                         f"{s['estimate_momentum'][source]:.3g})")
              for source in s["peak_torque"]],
            ("wheels", f"peak |h| {s['peak_total_momentum']:.3g} N m s over {s['hours']:g} h, "
                       f"{s['peak_wheel_momentum']:.3g} N m s on one wheel"),
            ("eclipses", f"{s['eclipse_days']} days of the year, up to {s['eclipse_max_fraction']:.1%} of an "
                         f"orbit (beta {s['beta_range_deg'][0]:.1f} to {s['beta_range_deg'][1]:.1f} deg)"),
            ("Monte Carlo", f"peak |h| over an orbit: median {s['monte_carlo_median']:.3g}, 95th percentile "
                            f"{s['monte_carlo_p95']:.3g} N m s ({s['monte_carlo_samples']} draws)"),
        ],
        ("budget.png",),
        (Option("--hours", "hours", float, 24.0, "Time of the budget run, h."),
         Option("--samples", "samples", int, 32, "Monte-Carlo draws over one orbit.",
                "tumble._validate:require_count")),
    ),
    "lorentz": Demo(
        "tumble.viz.lorentz:demo_lorentz",
        """Lorentz-factor inertia of a neutron star (R = 12 km, M = 1.4 Msun, period 1.4 ms).

        Incoherent matter in rigid rotation, special relativity only (not Born-rigid, no gravity:
        docs/limits.md): the corrections to I, L and T that the Newtonian model neglects, for the star
        as a uniform sphere, a shell and a ring. Writes lorentz.png (I/I0 against the rim speed).
        """,
        lambda s: [
            ("rim", f"omega = {s['omega']:.6g} rad/s, rim speed {s['rim_speed']:.4f} c"),
            *[(shape, f"I and L {s[shape]['moment']:+.3%}, kinetic energy {s[shape]['energy']:+.3%} "
                      "against Newton") for shape in ("sphere", "shell", "ring")],
        ],
        ("lorentz.png",),
    ),
    "chaos": Demo(
        "tumble.viz.chaos:demo_chaos",
        """Integrability and chaos of the heavy top: Lagrange, Kovalevskaya and a generic top at the same energy.

        Poincare sections (gamma1 = 0 crossed upwards, H = 1 J, L_z = 0) side by side: invariant curves for
        the two integrable tops, a chaotic sea for the generic one; and the finite-time largest Lyapunov
        exponent against time: -> 0 like ln t / t for the integrable tops, a plateau for the chaotic one
        (docs/chaos.md). Writes chaos.png in the directory.
        """,
        lambda s: [(name, f"largest exponent {value:.3g} 1/s after {s['duration_s']:g} s, "
                          f"{s['section_points'][name]} section points")
                   for name, value in s["largest_exponent"].items()],
        ("chaos.png",),
        (Option("--duration", "duration", float, 2000.0, "Integrated time of each top, s."),),
    ),
    "space-arm": Demo(
        "tumble.viz.space_arm:demo_space_arm",
        """A two-link arm on a free-floating hub swings through a commanded manoeuvre, and the hub turns.

        The hub (100 kg) is the floating base of the arm (no gravity, no external force); a PD law drives
        the joints along a minimum-jerk path to (90, -90) deg in 8 s. The joint torques are internal, so the
        total momentum stays zero and the hub turns and moves against the arm (Dubowsky & Papadopoulos
        1993). Writes space_arm.nc and space_arm.png (joint angles, hub rotation, total momentum).
        """,
        lambda s: [("hub", f"turned {s['hub_rotation_rad']:.6f} rad about z by the manoeuvre"),
                   ("tracking", f"largest joint error {s['max_tracking_error_rad']:.3g} rad"),
                   ("momentum", f"largest |L| {s['max_angular_momentum']:.2g} N m s, |p| "
                                f"{s['max_linear_momentum']:.2g} N s (exactly 0: internal torques)")],
        ("space_arm.nc", "space_arm.png"),
    ),
    "estimation": Demo(
        "tumble.viz.estimation:demo_estimation",
        """A slew and fine pointing with a star tracker and a gyro through the MEKF in the loop.

        The flight software samples a 10 arcsec star tracker and a gyro at 2 Hz, runs the MEKF and feeds
        its estimate to a quaternion PD law with a one-period computation delay; 40 runs over noise seeds,
        gyro biases and initial estimate errors (docs/estimation.md, "The flight-software loop"). Writes
        estimation_loop.png (knowledge error with its 3 sigma, control error) and estimation_spectra.png.
        """,
        lambda s: [("3 sigma", f"{s['inside_3sigma']:.2%} of the knowledge errors of {s['runs']} runs inside "
                               "the filter's 3 sigma"),
                   ("pointing", f"fine pointing RMS: knowledge {s['knowledge_rms_rad']:.2g} rad, control "
                                f"{s['control_rms_rad']:.2g} rad (correlation {s['correlation']:.2f})")],
        ("estimation_loop.png", "estimation_spectra.png"),
    ),
}
