"""Observer figures: OBS Fig. 2, the initial speed-error study, the gain study, sensor effects.

All adhesion values are plotted in the OBS convention (theta_obs = 1/theta_fm: 1 dry, larger =
less grip). Their reference checks (docs/models/observer_model.md §4-§9) are in
:mod:`tirecli.studies.checks.observer`.
"""
from __future__ import annotations

import numpy as np

from tirecli.figures.registry import register
from tirecli.figures.transient import require
from tirecli.figures.style import COLORS, finish, legend_room, new_figure, synthetic_mark

def _runs(result):
    require(result, "observe", "obs-*")
    return list(zip(result.payload["cases"], result.payload["trajectories"], result.payload["runs"]))


def _plot_runs(result, points: int = 2500):
    """``_runs`` with trajectories thinned to about ``points`` samples for plotting."""
    from dataclasses import fields, replace

    out = []
    for case, tr, run in _runs(result):
        k = max(1, len(tr.t) // points)
        idx = np.unique(np.r_[np.arange(0, len(tr.t), k), len(tr.t) - 1])
        arrays = {f.name: getattr(tr, f.name)[idx] for f in fields(tr) if isinstance(getattr(tr, f.name), np.ndarray)}
        out.append((case, replace(tr, **arrays), run))
    return out


def _slip(result, tr):
    from tirecli.conventions import slip_from_speeds

    return slip_from_speeds(tr.v, tr.omega, result.payload["plant"].car.r)


def _mark_synthetic(result, fig):
    if result.synthetic:
        synthetic_mark(fig)


# --------------------------------------------------------------------------- OBS Fig. 2


@register(
    "obs-fig2", paper="OBS", label="Fig. 2 (a), (b), (c)", study="obs-fig2", order=20,
    title="Observer simulation: adhesion and speed estimated from the wheel speed",
    caption="Quarter car with the lumped LuGre tire (OBS Fig. 1 parameters, kappa = 10 1/m, sigma2 in the vehicle "
            "equation only) and the observer of Theorem 1 (k1 = -k3 = 1000, k2 = 0, gamma = 2e5, alpha = 20), "
            "measuring the wheel speed only. (a) theta (solid) and theta_hat (dashed), OBS convention, with the v_r "
            "zero crossings dotted; (b) slip; (c) v (solid) and v_hat (dashed). The scenario (theta = 1 -> 5/3 step at "
            "5 s -> half-cosine to 2.5 over 10-15 s; torque +350/-250/+350 N m switched over 7-8 s and 12-13 s; "
            "v(0) = 20 m/s, v_hat(0) = v(0), theta_hat(0) = 1) is [assumed] (docs/models/observer_model.md §7): OBS does not print it. "
            "theta_hat stops moving near the crossing at 12.5 s, where v_r = 0 carries no information on theta, "
            "and re-converges once |v_r| grows.",
    paper_shows="(a) theta and its estimate over 20 s: dry, a sudden change to wet, a smooth change to snow, snow; "
                "vertical lines at the v_r zero crossings (7.5 s, 12.5 s); (b) smooth slip between 0 and 0.05 in "
                "magnitude; (c) vehicle speed and its estimate, indistinguishable.",
)
def draw_obs_fig2(result):
    fig, (a, b, c) = new_figure(nrows=3, width=7.2, height=8.4, sharex=True)
    log = result.payload.get("log", False)   # the observer on a measured log: no true theta, v measured
    for k, (case, tr, run) in enumerate(_plot_runs(result)):
        col = COLORS[k % len(COLORS)]
        suffix = f" ({case.label})" if len(result.payload["cases"]) > 1 else ""
        if k == 0 and not log:
            a.plot(tr.t, tr.theta, color="k", lw=1.6, label="theta (true)")
        a.plot(tr.t, tr.theta_hat, "--", color=col, lw=1.4, label="theta_hat" + suffix)
        for tc in run["metrics"].get("crossings_s", []):
            a.axvline(tc, color=col, ls=":", lw=1.0)
        if log:
            b.plot(tr.t, tr.torque, color=col, label="torque (log)" if k == 0 else None)
        else:
            b.plot(tr.t, _slip(result, tr), color=col, label="slip s" + suffix)
        if k == 0 and not np.all(np.isnan(tr.v)):
            c.plot(tr.t, tr.v, color="k", lw=1.6, label="v (measured)" if log else "v (true)")
        c.plot(tr.t, tr.v_hat, "--", color=col, lw=1.4, label="v_hat" + suffix)
    if log:
        finish(a, "", "theta (OBS convention) [-]", "(a) road adhesion estimated from the log", loc="upper left")
        finish(b, "", "wheel torque [N m]", "(b) wheel torque of the log (held between samples)")
        finish(c, "time t [s]", "speed [m/s]", "(c) vehicle speed: measured and estimated", loc="upper left")
        _mark_synthetic(result, fig)
        return fig
    crossings = _plot_runs(result)[0][2]["metrics"]["crossings_s"]
    txt = ", ".join(f"{tc:.3f} s" for tc in crossings)
    finish(a, "", "theta (OBS convention) [-]", f"(a) road adhesion; dotted: v_r = 0 at {txt}", loc="upper left")
    finish(b, "", "slip s [-]", "(b) slip (> 0 accelerating, < 0 braking)")
    b.axhline(0.0, color="0.5", lw=0.8)
    finish(c, "time t [s]", "speed [m/s]", "(c) vehicle speed and its estimate", loc="upper left")
    _mark_synthetic(result, fig)
    return fig


# --------------------------------------------------------------------------- speed-error study


def _slow_mode_note(result) -> str:
    """The slow mode of the first 'theta known' case (computed by the study, :func:`tirecli.studies.observe.running.slow_mode`)."""
    for case, _, _ in _runs(result):
        if case.label.startswith("theta known"):
            sm = result.payload.get("slow_mode", {}).get(case.label)
            if sm is None:  # adaptation on: the theta-known linearisation does not apply
                return ""
            return f"fitted {sm['fitted_1_s']:.4f} 1/s; linearised along the run {sm['linearised_1_s']:.4f} 1/s"
    return ""


@register(
    "obs-speed-error", paper="OBS", label="§8: initial speed error", study="obs-speed-error", order=21,
    title="An initial speed error: the slow speed mode and the theta bias",
    caption="Fig. 2 scenario with Ua = Ub = 250 N m (less slip, docs/models/observer_model.md §8) started with v_hat(0) = v(0), "
            "v(0) + 0.1 m/s and v(0) + 2 m/s, and with theta known (gamma = 0, dry road). (a) |v_hat - v|: the speed "
            "estimate is essentially dead reckoning of eta = r m v + J omega, so the error decays with the slow pole "
            "-(F_n sigma2/m + k1/(r m |k3|)) = -0.0294 1/s of A - K C (dotted: e^(-0.0294 t); time constant 34 s) and "
            "0.063 m/s of the 0.1 m/s remain after 20 s. (b), (c) theta_hat: a speed error biases the estimated slip "
            "velocity v_r, which the observer compensates with a wrong theta_hat (weak joint observability): -0.17 at "
            "4.9 s instead of 1 and 1.34 instead of 2.5 at 20 s for +0.1 m/s; about -11 for +2 m/s. Raising k1 speeds "
            "up the slow mode but does not remove the ambiguity. Shown as computed, not tuned away.",
    paper_shows="Not a figure of OBS: the paper's Fig. 2 starts from the exact speed. docs/models/observer_model.md §8 documents this "
                "sensitivity of its scheme.",
)
def draw_obs_speed_error(result):
    fig, (a, b, c) = new_figure(nrows=3, width=7.2, height=8.6)
    runs = _plot_runs(result)
    for k, (case, tr, run) in enumerate(runs):
        col = COLORS[k % len(COLORS)]
        err = np.abs(tr.v_hat - tr.v)
        if case.scenario.vhat0 != case.scenario.v0:
            a.semilogy(tr.t, np.maximum(err, 1e-7), color=col, label=case.label)
        big = np.max(np.abs(tr.theta_hat)) > 5
        ax = c if big else b
        if not case.label.startswith("theta known"):
            ax.plot(tr.t, tr.theta_hat, "--", color=col, label=f"theta_hat, {case.label}")
    tr0 = runs[0][1]
    t = tr0.t
    for case, tr, _ in runs:
        if case.label.startswith("theta known"):
            e0 = abs(case.scenario.vhat0 - case.scenario.v0)
            a.semilogy(t, e0 * np.exp(-0.0294 * t), "k:", lw=1.2, label="e^(-0.0294 t) (slow pole of A - K C)")
    b.plot(tr0.t, tr0.theta, "k", lw=1.6, label="theta (true)")
    c.plot(tr0.t, tr0.theta, "k", lw=1.6, label="theta (true)")
    note = _slow_mode_note(result)
    finish(a, "", "|v_hat - v| [m/s]", "(a) speed error" + (f" ({note})" if note else ""))
    finish(b, "", "theta (OBS) [-]", "(b) adhesion estimate, small speed errors", loc="lower right")
    legend_room(c, 0.35)
    finish(c, "time t [s]", "theta (OBS) [-]", "(c) adhesion estimate, large speed error", loc="lower left")
    _mark_synthetic(result, fig)
    return fig


# --------------------------------------------------------------------------- gain study


@register(
    "obs-gain-study", paper="OBS", label="gain study", study="obs-gain-study", order=22,
    title="Convergence time of theta_hat against an observer gain",
    caption="The first half of the Fig. 2 scenario (dry -> wet step at 5 s, then braking) run for several values of "
            "one gain (the others as OBS). (a) theta_hat; (b) time after the step until |theta_hat - theta| stays "
            "below the settling band, against the gain. Small gains leave theta_hat short of theta until braking "
            "raises |v_r| after the zero crossing near 7.4 s (convergence speed grows with excitation). Scenario "
            "values are [assumed] (docs/models/observer_model.md §7).",
    paper_shows="Not in OBS (the paper shows one gain set).",
)
def draw_obs_gain_study(result):
    from tirecli.errors import UsageError
    from tirecli.parameters.kinds import KINDS

    require(result, "observe", "obs-gain-study")
    if "gain_study" not in result.data:
        raise UsageError("figure 'obs-gain-study' needs a 'gain_study' block in the config")
    gs = result.data["gain_study"]
    gain = result.meta["gain_study"]["gain"]
    unit = KINDS["observer"].fields[gain].unit or "-"
    values = gs["value"].to_numpy(dtype=float)
    fig, (a, b) = new_figure(nrows=2, width=7.0, height=7.0)
    for k, ((_, tr, _), value) in enumerate(zip(_plot_runs(result), values)):  # the runs in the order of the values
        if k == 0:
            a.plot(tr.t, tr.theta, "k", lw=1.6, label="theta (true)")
        a.plot(tr.t, tr.theta_hat, "--", color=COLORS[k % len(COLORS)], label=f"{gain} = {_short(value)} {unit}")
    b.plot(values, gs["settle_time_s"], "o-", color=COLORS[0])
    if np.all(values > 0):
        b.set_xscale("log")
        b.set_xticks(values, [_short(x) for x in values])
        b.minorticks_off()
    tol = result.payload["metrics"]["settle_tolerance"]
    finish(a, "time t [s]", "theta (OBS) [-]", "(a) adhesion estimate", loc="lower right")
    finish(b, f"observer gain {gain} [{unit}]", "settling time [s]", f"(b) time to |theta_hat - theta| < {tol:g} after the first change",
           legend=False)
    _mark_synthetic(result, fig)
    return fig


def _short(x: float) -> str:
    """A gain value in few characters: ``5e4``, ``1.5e5``, ``20``."""
    return f"{x:.3g}".replace("e+0", "e").replace("e+", "e").replace("e-0", "e-")


# --------------------------------------------------------------------------- sensor effects


@register(
    "obs-noise", paper="OBS", label="sensor effects", study="obs-noise", order=23,
    title="Sampling, noise and encoder quantisation of the wheel-speed measurement",
    caption="First half of the Fig. 2 scenario with the wheel speed sampled at 1 kHz and held (zero-order hold), "
            "with seeded Gaussian noise (synthetic measurement), and from a 48-tooth encoder timed by a 1 MHz clock. "
            "Each jump D of the held measurement excites the observer's fast mode (rate lambda_f = 3.9e6 1/s) and "
            "the alpha y~^2 term of the adaptation law adds gamma alpha D^2/(2 lambda_f) > 0 to theta_hat: the "
            "steps and the noise are rectified into an upward bias of theta_hat (less grip estimated), growing with "
            "the noise variance and the sampling rate. (a) theta_hat; (b) measurement error y_m - omega; "
            "(c) v_hat - v. Cases whose adhesion error is several times larger than the others' (here the 0.05 "
            "rad/s noise and the encoder) get a column of their own; the start-up of the sampled measurement (its "
            "first 1 % of time) is left off the error scale.",
    paper_shows="Not in OBS (the paper assumes a continuous, exact wheel speed).",
)
def draw_obs_noise(result):
    runs = list(_plot_runs(result))
    groups = _split_by_size(runs)
    fig, axes = new_figure(nrows=3, ncols=len(groups), width=7.2 if len(groups) == 1 else 11.0, height=8.4,
                           sharex=True)
    axes = np.asarray(axes).reshape(3, len(groups))
    colour = {id(case): COLORS[k % len(COLORS)] for k, (case, _, _) in enumerate(runs)}
    for j, group in enumerate(groups):
        a, b, c = axes[:, j]
        # in (b) and (c) the smaller errors are drawn on top of the larger (noisy) ones
        size = [float(np.sqrt(np.mean(np.square(tr.y - tr.omega)))) for _, tr, _ in group]
        on_top = {k: 2.0 + r for r, k in enumerate(sorted(range(len(group)), key=lambda k: -size[k]))}
        for k, (case, tr, _) in enumerate(group):
            col = colour[id(case)]
            if k == 0:
                a.plot(tr.t, tr.theta, "k", lw=1.6, label="theta (true)" if j == 0 else None)
            a.plot(tr.t, tr.theta_hat, "--", color=col, label=case.label)
            b.plot(tr.t, tr.y - tr.omega, color=col, lw=0.6, zorder=on_top[k])
            c.plot(tr.t, tr.v_hat - tr.v, color=col, lw=0.9, zorder=on_top[k])
        _clip_start(b, [(tr.t, tr.y - tr.omega) for _, tr, _ in group], "rad/s")
        which = "" if len(groups) == 1 else (" (larger errors)" if j else " (smaller errors)")
        finish(a, "", "theta (OBS) [-]" if j == 0 else "", "(a) adhesion estimate" + which, legend=False)
        finish(b, "", "y_m - omega [rad/s]" if j == 0 else "", "(b) measurement error" + which, legend=False)
        finish(c, "time t [s]", "v_hat - v [m/s]" if j == 0 else "", "(c) speed error" + which, legend=False)
    handles, labels = [], []
    for ax in axes[0]:
        h, lab = ax.get_legend_handles_labels()
        handles, labels = handles + h, labels + lab
    fig.legend(handles, labels, loc="outside lower center", ncol=3, fontsize=8, frameon=False)
    _mark_synthetic(result, fig)
    return fig


def _split_by_size(runs, gap: float = 3.0) -> list:
    """The runs in one group, or two when their adhesion errors (RMS of theta_hat - theta) fall apart by
    more than ``gap`` times: the larger ones get panels of their own so the smaller stay readable."""
    err = [float(np.sqrt(np.mean(np.square(tr.theta_hat - tr.theta)))) for _, tr, _ in runs]
    floor = 1e-3 * max(err, default=0.0) + 1e-12   # errors below a thousandth of the largest count as equal
    err = [max(e, floor) for e in err]
    order = sorted(range(len(runs)), key=lambda k: err[k])
    ratios = [err[order[i + 1]] / err[order[i]] for i in range(len(order) - 1)]
    if not ratios or max(ratios) < gap:
        return [runs]
    cut = int(np.argmax(ratios)) + 1
    small = set(order[:cut])
    return [[r for k, r in enumerate(runs) if k in small], [r for k, r in enumerate(runs) if k not in small]]


def _clip_start(ax, curves, unit: str, skip: float = 0.01) -> None:
    """Scale ``ax`` to the curves after their first ``skip`` fraction of time (the start-up of a sampled
    measurement can be far larger than what follows) and note the values left off the scale."""
    lo = min(float(np.min(y[t >= t[0] + skip * (t[-1] - t[0])])) for t, y in curves)
    hi = max(float(np.max(y[t >= t[0] + skip * (t[-1] - t[0])])) for t, y in curves)
    full_lo = min(float(np.min(y)) for _, y in curves)
    full_hi = max(float(np.max(y)) for _, y in curves)
    pad = 0.08 * (hi - lo or 1.0)
    if full_lo < lo - pad or full_hi > hi + pad:
        ax.set_ylim(lo - pad, hi + pad)
        off = [f"{v:.3g}" for v in (full_lo, full_hi) if v < lo - pad or v > hi + pad]
        ax.text(0.99, 0.03, f"start-up off scale: {', '.join(off)} {unit}", transform=ax.transAxes, ha="right",
                va="bottom", fontsize=7, color="0.35")
