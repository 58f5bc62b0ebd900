"""MCPS figures (Sorine & Szymanski 2000): Figs. 1-6, the relaxation run and the parameter table
(``docs/models/mcps_tire.md``); Figs. 7-11 and the calibration card are in
:mod:`tirecli.figures.mcps_stationary` (imported here, so every ``mcps-`` figure registers with this module).

Forces are computed in ISO-W, road on tire (:mod:`tirecli.models.mcps.tire`). Slip angles are drawn in
degrees, slips in percent.

Their reference checks (model checks against closed forms and linear stiffnesses, reference checks
against docs/models/mcps_tire.md §11) are in :mod:`tirecli.studies.checks.mcps`.
"""
from __future__ import annotations

import math

import numpy as np

import tirecli.figures.mcps_stationary  # noqa: F401  (registers Figs. 7-11 and the calibration card)
from tirecli.figures.mcps_common import legend_below, tire_name, tire_text, require
from tirecli.figures.registry import Table, register
from tirecli.figures.style import COLORS, LINESTYLES, finish, new_figure, suptitle

DEG = math.pi / 180.0


def _caption_fig3(result):
    if result is None:
        vals = "U = 1 cm^2 under the 4000 N patch pressure: K = 5000 N/m, F_k = 19.8 N, S_z = 0.35 N m/rad, M_kz = 0.187 N m"
        motion, periods = "A = 8 F_k/K, Psi = 8 M_kz/S_z", "T = 2 s (solid, exact increments) and T = 0.5 s (dashed, eq. 9 integrated in time)"
        frame = "off"
    else:
        f, sc = result.meta["facts"], result.meta["scenario"]
        vals = (f"U = {result.payload['params'].U:g} m^2 under {f['pressure_Pa'] / 1e3:.4g} kPa: K = {f['K_N_per_m']:.4g} N/m, "
                f"F_k = {f['Fk_N']:.4g} N, S_z = {f['Sz_Nm_per_rad']:.4g} N m/rad, M_kz = {f['Mkz_Nm']:.4g} N m")
        motion = f"A = {1e3 * f['amplitude_m']:.4g} mm, Psi = {f['rotation_rad']:.4g} rad"
        per = sc["periods_s"]
        periods = f"T = {per[0]:g} s (solid, exact increments)" + (
            f" and T = {per[1]:g} s (dashed, eq. 9 integrated in time)" if len(per) > 1 else "")
        frame = "on" if sc["frame_term"] else "off"
    return (f"One slider ({vals}; {tire_text(result)}) driven by u_x = A sin(2 pi t/T), psi = Psi sin(2 pi t/T), "
            f"{motion} [assumed scenario], frame-rotation term {frame}. Force and torque are what the slider transmits to "
            "the road (MCPS eq. 9). Initial slope K (S_z), overshoot above the Coulomb level on first loading (4/3 F_k "
            f"with alpha = 3, beta = 1.5) and more after each reversal (limit 5/3 F_k), then the Coulomb level. {periods}: "
            "coinciding loops show that the law is rate independent.")


def _standstill_text(result):
    if result is None:
        return "4000 N, |yaw rate| = 1 rad/s, psi = 0 -> +0.45 -> -0.45 -> +0.45 rad [assumed amplitude], frame-rotation term on"
    sc = result.meta["scenario"]
    A = sc["amplitude_rad"]
    return (f"{sc['fz_N']:g} N, |yaw rate| = {sc['yaw_rate_rad_per_s']:g} rad/s, psi = 0 -> +{A:.3g} -> -{A:.3g} rad, "
            f"{sc['cycles']} cycle(s)" + (" [assumed amplitude: the scan's '-45 <= psi <= 45' read as +-0.45 rad]"
                                           if abs(A - 0.45) < 1e-8 else "")
            + f", frame-rotation term {'on' if sc['frame_term'] else 'off'}")


def _caption_fig4(result):
    return (f"Blocked wheel (V = 0, rigid belt; {_standstill_text(result)}; {tire_text(result)}). Top: the lateral "
            "force density f_y(xi, t) of the road on the tire (ISO-W; odd in xi) as a map over the patch and time (the "
            "paper's surface seen from above; dotted: |f_y| = F'_ky); below: profiles at the yaw reversals over F'_ky "
            "(the lines of their colours on the map). Near the centre f_y grows with |xi| psi; the edges saturate "
            "first, with an overshoot on first loading (4/3 F'_ky without the frame term) and a larger one after each "
            "reversal (limit 5/3 F'_ky).")


def _caption_fig5(result):
    return (f"Mz (road on tire, ISO) against the yaw angle psi for the Fig. 4 motion ({_standstill_text(result)}; "
            f"{tire_text(result)}). Linear start with slope -C_z (eq. 11, dashed), saturation towards -sgn(yaw rate) times "
            "the asymptotic torque (dotted: with the frame term; dash-dot: eq. 12, without it) with overshoot, a larger "
            "overshoot after each reversal, and a loop that settles to a periodic one within a few cycles (the first is not "
            "symmetric). The Magic Formula has no torque at standstill. The scan's torque ticks suggest the paper's tire "
            "gives about half the torques of the default tire.")


def _caption_relaxation(result):
    if result is None:
        scen, cases = "at 20 m/s, Vy steps to Vx tan(1 deg)", "the solid carcass, the complete model, and the complete model with the twist locked"
    else:
        sc = result.meta["scenario"]
        scen = f"at {sc['speed_m_per_s']:g} m/s, Vy steps to Vx tan({sc['alpha_rad'] / DEG:.3g} deg) ({sc['fz_N']:g} N)"
        cases = ", ".join(c["label"] for c in result.meta["cases"])
    return (f"From free rolling {scen} at t = 0 [assumed scenario]; Fy/Fy_inf (left) and Mz (right) against the rolled "
            f"distance, frame-rotation term on; cases: {cases}; {tire_text(result)}. The solid carcass is exact by "
            "characteristics and steady after one patch length. With the default tire at 20 m/s and 1 deg the complete "
            "model is not monotone (about 72 % at 0.08 m, a dip to about 25 % near 0.19 m, then a slow rise, 95 % near "
            "0.78 m): the dip is the lateral belt mode y, it stays with the twist locked (63 % first reached at 0.309 m) "
            "and vanishes when y is locked. Transport by Lagrangian tread elements (CFL = 1), second order. The Magic "
            "Formula, a stationary model, cannot give this build-up.")


@register(
    "mcps-table", paper="MCPS", label="parameters", study="mcps-fig7-9", order=1,
    title="Default MCPS tire (all values assumed)",
    caption="The built-in set sorine2000-mcps: the paper gives the model's structure but no parameter values, so every "
            "value is a documented default (a 165/65R14-like passenger tire, docs/models/mcps_tire.md §9), overridable with "
            "--set tire.NAME=VALUE.",
    paper_shows="No parameter table: the MCPS paper prints no values.",
)
def draw_table(result):
    from tirecli.figures.steady import parameter_table

    return parameter_table(result.parameter_sets["tire"])


# --------------------------------------------------------------------------- Fig. 3 (slider)


@register(
    "mcps-fig3", paper="MCPS", label="Fig. 3", study="mcps-fig3", order=30,
    title="Rubber slider: friction force and torsional torque loops",
    caption=_caption_fig3,
    paper_shows="Friction force and torque of one rubber slider: hysteresis loops with overshoot (no scales legible).",
)
def draw_fig3(result):
    require(result, "mcps-slider", "mcps-fig3")
    df = result.data["slider"]
    f = result.meta["facts"]
    periods = result.payload["periods"]
    fig, (a, b) = new_figure(ncols=2, width=11.0, height=4.4)
    for i, T in enumerate(periods):
        g = df[df["period"] == T]
        kw = {"color": COLORS[i], "ls": LINESTYLES[i % len(LINESTYLES)], "lw": 1.5 if i == 0 else 1.1}
        a.plot(1e3 * g["ux"], g["fx"], label=f"T = {T:g} s", **kw)
        b.plot(g["psi"], g["m"], label=f"T = {T:g} s", **kw)
    for ax, lev, lim in ((a, f["Fk_N"], f["reversal_limit_force_N"]), (b, f["Mkz_Nm"], None)):
        for s_ in (1, -1):
            ax.axhline(s_ * lev, color="#777777", lw=0.8, ls=":")
            if lim:
                ax.axhline(s_ * lim, color="#B00020", lw=0.6, ls=":")
    # one legend (the periods are the same in both panels), in the torque panel: the force panel's free corner
    # holds the red limit line
    finish(a, "displacement u_x [mm]", "friction force f_x [N]", "force (dotted: +-F_k; red: limit 5/3 F_k)",
           legend=False)
    finish(b, "rotation psi [rad]", "friction torque m [N m]", "torque (dotted: +-M_kz)")
    fig.suptitle(f"MCPS Fig. 3: one rubber slider, {tire_name(result)}", fontsize=10)
    return fig


# --------------------------------------------------------------------------- Figs. 4-5 (standstill)


@register(
    "mcps-fig4", paper="MCPS", label="Fig. 4", study="mcps-fig4-5", order=40,
    title="Lateral friction force distribution over the patch at standstill",
    caption=_caption_fig4,
    paper_shows="Surface plot of the lateral friction-force distribution over the patch against time, V = 0, |yaw rate| = "
                "1 rad/s.",
)
def draw_fig4(result):
    require(result, "mcps-standstill", "mcps-fig4")
    df = result.data["patch"]
    f = result.meta["facts"]
    Fk = f["Fky_per_length_N_per_m"]
    times = np.unique(df["t"].to_numpy())
    xi = np.unique(df["xi"].to_numpy())
    Z = df.sort_values(["t", "xi"])["fy"].to_numpy().reshape(times.size, xi.size) / 1e3
    # the paper's surface f_y(xi, t) as a map over the same plane (top), the profiles at the reversals
    # below it on the same xi axis; the reversal times are lines of the profiles' colours on the map
    fig, (a, b) = new_figure(nrows=2, width=6.8, height=8.2, sharex=True, height_ratios=(1.25, 1.0))
    lim = max(float(np.abs(Z).max()), 5.0 / 3.0 * Fk / 1e3)
    mesh = a.pcolormesh(1e3 * xi, times, Z, cmap="RdBu_r", vmin=-lim, vmax=lim, shading="nearest", rasterized=True)
    fig.colorbar(mesh, ax=a, label="f_y [kN/m]", pad=0.02)
    a.contour(1e3 * xi, times, Z, levels=[-Fk / 1e3, Fk / 1e3], colors="#000000", linewidths=0.7, linestyles=":")
    a.plot([], [], color="#000000", lw=0.7, ls=":", label="|f_y| = F'_ky (map)")
    st = result.data["standstill"]
    ends = st.groupby("leg")["t"].max().to_numpy()
    for i, te in enumerate(ends[:4]):
        k = int(np.argmin(np.abs(times - te)))
        ps = float(st["psi"].iloc[int(np.argmin(np.abs(st["t"].to_numpy() - te)))])
        col = COLORS[i % len(COLORS)]
        a.axhline(times[k], color=col, lw=1.4)
        b.plot(1e3 * xi, Z[k] * 1e3 / Fk, color=col, lw=1.5, label=f"t = {te:.2f} s, psi = {ps:+.3g} rad")
    for lev in (4 / 3, 5 / 3):
        for s_ in (1, -1):
            b.axhline(s_ * lev, color="#777777", lw=0.7, ls=":")
    finish(a, "", "time t [s]", "f_y(xi, t), road on tire (lines: the reversals drawn below)", legend=False)
    finish(b, "patch abscissa xi [mm] (forward)", "f_y / F'_ky [-]", "profiles at the reversals (dotted: 4/3, 5/3)",
           legend=False)
    a.grid(False)
    handles = b.get_legend_handles_labels()[0] + a.get_legend_handles_labels()[0]
    labels = b.get_legend_handles_labels()[1] + a.get_legend_handles_labels()[1]
    fig.legend(handles, labels, loc="outside lower center", ncol=2, fontsize=8, frameon=False)
    suptitle(fig, f"MCPS Fig. 4: lateral friction force distribution at standstill, {tire_name(result)}")
    return fig


@register(
    "mcps-fig5", paper="MCPS", label="Fig. 5", study="mcps-fig4-5", order=50,
    title="Tire torsional torque at standstill: Mz against the yaw angle",
    caption=_caption_fig5,
    paper_shows="Torsional torque against the yaw angle (rad, ticks -0.4 to 0.4): a hysteresis loop.",
)
def draw_fig5(result):
    require(result, "mcps-standstill", "mcps-fig5")
    st = result.data["standstill"]
    f = result.meta["facts"]
    fig, ax = new_figure(width=6.8, height=4.6)
    for c, g in st.groupby("cycle"):
        lo = g.index[0] - 1 if g.index[0] > 0 else g.index[0]
        g = st.loc[lo:g.index[-1]]
        ax.plot(g["psi"], g["mz"], color=COLORS[int(c) % len(COLORS)], lw=1.4,
                label="first loading" if c == 0 else f"cycle {int(c)}")
    A = result.meta["scenario"]["amplitude_rad"]
    ps = np.linspace(-0.15 * A, 0.15 * A, 3)
    ax.plot(ps, -f["C_z_eq11_Nm_per_rad"] * ps, color="#000000", ls="--", lw=0.9, label="slope -C_z (eq. 11)")
    for s_ in (1, -1):
        ax.axhline(s_ * f["Mz_inf_frame_term_Nm"], color="#777777", ls=":", lw=0.9)
        ax.axhline(s_ * f["Mz_inf_eq12_Nm"], color="#777777", ls="-.", lw=0.7)
    ax.plot([], [], color="#777777", ls=":", lw=0.9, label="+-asymptotic torque, frame term on")
    ax.plot([], [], color="#777777", ls="-.", lw=0.7, label="+-eq. (12), frame term off")
    finish(ax, "yaw angle psi [rad]", "aligning torque Mz [N m] (ISO, road on tire)",
           f"MCPS Fig. 5: torque at standstill, {tire_name(result)}", legend=False)
    legend_below(fig, ax, ncol=3)
    return fig


# --------------------------------------------------------------------------- relaxation


@register(
    "mcps-relaxation", paper="MCPS", label="relaxation", study="mcps-relaxation", order=130,
    title="Relaxation: side-force build-up over the rolled distance after a 1 deg slip-angle step",
    caption=_caption_relaxation,
    paper_shows="No paper figure: the paper states that MCPS reproduces relaxation-length behaviour.",
)
def draw_relaxation(result):
    require(result, "mcps-relaxation", "mcps-relaxation")
    df = result.data["relaxation"]
    fig, (a, b) = new_figure(ncols=2, width=11.0, height=4.4)
    for i, case in enumerate(result.meta["cases"]):
        lab = case["label"]
        g = df[df["case"] == lab]
        kw = {"color": COLORS[i % len(COLORS)], "ls": LINESTYLES[i % len(LINESTYLES)], "lw": 1.4}
        a.plot(g["s"], g["ratio"], label=lab, **kw)
        b.plot(g["s"], g["mz"], label=lab, **kw)
        f = result.meta["facts"][lab]
        for k, mk in (("s63_first_m", "o"), ("s95_first_m", "s")):
            if f[k] is not None:
                a.plot([f[k]], [float(k[1:3]) / 100.0], marker=mk, color=kw["color"], ms=4, ls="none")
    for lev in (0.63, 0.95, 1.0):
        a.axhline(lev, color="#777777", lw=0.7, ls=":")
    sc = result.meta["scenario"]
    smax = min(float(df["s"].max()), 1.5)
    for ax in (a, b):
        ax.set_xlim(0, smax)
    finish(a, "rolled distance s [m]", "Fy / Fy_inf [-]", "side force (markers: first 63 % and 95 %)", legend=False)
    finish(b, "rolled distance s [m]", "Mz [N m] (ISO)", "aligning torque", legend=False)
    legend_below(fig, a, ncol=4)
    fig.suptitle(f"MCPS relaxation: alpha = {sc['alpha_rad'] / DEG:.3g} deg at {sc['speed_m_per_s']:g} m/s, "
                 f"{tire_name(result)}", fontsize=10)
    return fig


__all__ = ["require"]


# --------------------------------------------------------------------------- schematics (Figs. 1, 2, 6) as tables


@register(
    "mcps-fig1-2", paper="MCPS", label="Figs. 1-2", study="mcps-fig4-5", order=10,
    title="Rubber slider and contact patch: geometry and the quantities of the model",
    caption="The paper's Figs. 1 and 2 are drawings (a slider of area U with its frame R_D; the patch of length l and "
            "width w in the tire frame R_W with the rim's translation V and yaw rate). tirecli lists what they define, "
            "with the values of the run's tire at its load: patch, pressure, the slider of Fig. 3 and the per-length "
            "constants of the blocked-wheel model (docs/models/mcps_tire.md §1, §4, §5).",
    paper_shows="Fig. 1: rubber slider geometry and referential; Fig. 2: contact patch geometry and tire referential "
                "(schematics, no data).",
)
def draw_geometry(result):
    from tirecli.errors import UsageError

    if "params" not in (result.payload or {}) or "patch" not in (result.payload or {}):
        raise UsageError("figure 'mcps-fig1-2' draws an 'mcps-standstill' run (see 'tirecli figures list')")
    p, pa, law = result.payload["params"], result.payload["patch"], result.payload["law"]
    sl = p.slider_law(pa.P)
    rows = [
        ["F_z", f"{pa.fz:g}", "N", "vertical load"],
        ["l", f"{pa.l:.4g}", "m", "patch length along X_W (l_ref (F_z/fz_ref)^l_exponent)"],
        ["w", f"{pa.w:.4g}", "m", "patch width along Y_W"],
        ["P", f"{pa.P:.5g}", "Pa", "uniform contact pressure F_z/(w l)"],
        ["U", f"{p.U:.3g}", "m^2", "area of the slider of Fig. 3 (frame R_D)"],
        ["K_x, K_y", f"{sl.K[0]:.5g}, {sl.K[1]:.5g}", "N/m", "slider stiffness U r"],
        ["F_kx, F_ky", f"{sl.Fk[0]:.5g}, {sl.Fk[1]:.5g}", "N", "slider Coulomb levels P U mu"],
        ["S_z, M_kz", f"{sl.Sz:.4g}, {sl.Mkz:.4g}", "N m/rad, N m", "slider torsional stiffness and sliding torque"],
        ["K'_x, K'_y", f"{law.K[0]:.5g}, {law.K[1]:.5g}", "N/m^2", "patch stiffness per length w r"],
        ["F'_kx, F'_ky", f"{law.Fk[0]:.5g}, {law.Fk[1]:.5g}", "N/m", "patch Coulomb levels per length mu P w"],
        ["S'_z, M'_kz", f"{law.Sz:.5g}, {law.Mkz:.5g}", "N m/rad/m, N m/m", "torsion of a strip per length (eq. 11-12)"],
    ]
    return Table(columns=["symbol", "value", "unit", "meaning"], rows=rows,
                 notes=[f"Tire {tire_name(result)}; ISO-W axes: X_W forward, Y_W left, Z_W up, origin at the patch centre."])


@register(
    "mcps-fig6", paper="MCPS", label="Fig. 6", study="mcps-relaxation", order=60,
    title="System with carcass flexibility: the belt's degrees of freedom",
    caption="The paper's Fig. 6 is a drawing of the belt on the rim: translations x, y and twist delta, each on a spring "
            "and a damper (MCPS eqs. 16-17). tirecli lists them with the run's values, the belt's natural frequencies "
            "on its springs alone and with the tread elements acting as springs to the road, and the damping ratios "
            "(docs/models/mcps_tire.md §7).",
    paper_shows="Fig. 6: the system with carcass flexibility (schematic, no data).",
)
def draw_belt(result):
    from tirecli.errors import UsageError

    if result.study not in ("mcps-relaxation", "mcps-stationary") or "params" not in (result.payload or {}):
        raise UsageError("figure 'mcps-fig6' draws an 'mcps-relaxation' or 'mcps-stationary' run")
    p = result.payload["params"]
    fz = result.meta.get("scenario", {}).get("fz_N") or result.meta.get("loads", [4000.0])[0]
    pa, law, cz = p.patch(fz), p.patch_law(fz), p.stiffnesses(fz)["C_z"]
    rows, coupled = [], []
    for dof, m, k, c, kp, unit_k, unit_c in (
            ("x", p.m_b, p.k_x, p.c_x, law.K[0] * pa.l, "N/m", "N s/m"),
            ("y", p.m_b, p.k_y, p.c_y, law.K[1] * pa.l, "N/m", "N s/m"),
            ("delta", p.J_b, p.k_delta, p.c_delta, cz, "N m/rad", "N m s/rad")):
        coupled.append(math.sqrt((k + kp) / m))
        rows.append([dof, f"{m:g}", f"{k:.4g} {unit_k}", f"{c:.4g} {unit_c}", f"{c / (2 * math.sqrt(k * m)):.3f}",
                     f"{math.sqrt(k / m):.1f}", f"{coupled[-1]:.1f}"])
    # the fastest rate with the patch as a spring is tirecli.numerics.mcps_transient.coupling_rate (no DOF locked)
    return Table(columns=["DOF", "mass / inertia", "stiffness", "damping", "damping ratio",
                          "natural rate on the rim [rad/s]", "with the patch as a spring [rad/s]"], rows=rows,
                 notes=[f"Tire {tire_name(result)} at {fz:g} N; the fastest rate ({max(coupled):.0f} rad/s) sets the "
                        "transport step of the relaxation runs (docs/models/mcps_tire.md §7)."])
