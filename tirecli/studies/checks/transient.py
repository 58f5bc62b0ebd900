"""Reference checks of the transient figures FM Figs. 4, 7, 8: the brakings of the quarter car and the
open-loop errors of the lumped models (``docs/models/lugre_friction.md`` §7, §10)."""
from __future__ import annotations

import numpy as np

from tirecli.studies.base import Check
from tirecli.studies.simulate_runs import (BRAKINGS, LOCK_1100, LUMPED_950, LUMPED_1050, LUMPED_Z_COUPLED,
                                          STEP_RELEASE, open_loop_errors, open_loop_of, run_of, variant_tag)


def _min_slip(tr):
    i = int(np.argmin(tr.out["slip"]))
    return float(tr.out["slip"][i]), float(tr.t[i])


def fig4_checks(result):
    out = []
    src = "docs/models/lugre_friction.md §7, §10 (FM Fig. 4)"
    tr = run_of(result, BRAKINGS[1])
    if tr is not None:
        smin, ts = _min_slip(tr)
        out += [
            Check("smin-1000", "min slip, PDE, T_max = 1000 N m (braking #2)", smin, -0.1777, 3e-4, "-", src),
            Check("t-smin-1000", "time of the min slip (after the window start)", ts, 2.00, 0.01, "s", src),
            Check("mumax-1000", "max |mu|, PDE, T_max = 1000 N m", float(np.max(np.abs(tr.out["mu"]))), 1.1663, 3e-4,
                  "-", "docs/models/lugre_friction.md §7"),
            Check("v3-1000", "vehicle speed at 3 s, T_max = 1000 N m", float(np.interp(3.0, tr.t, tr.y[:, 0])), 6.33,
                  0.01, "m/s", src),
        ]
    for lab, ref, tag in ((LUMPED_950, -0.148, "950"), (LUMPED_1050, -0.232, "1050")):
        tr = run_of(result, lab)
        if tr is not None:
            out.append(Check(f"smin-{tag}-lumpedZ", f"min slip, lumped kappa0(Z), T_max = {tag} N m", _min_slip(tr)[0],
                             ref, 1e-3, "-", src))
            out.append(Check(f"nolock-{tag}", f"number of wheel locks, T_max = {tag} N m", float(len(tr.events["lock"])),
                             0.0, 0.0, "-", src))
    tr = run_of(result, LOCK_1100)
    if tr is not None:
        t_lock = tr.events["lock"][0][0] if tr.events["lock"] else float("nan")
        out.append(Check("lock-1100", "time the wheel locks, T_max = 1100 N m", t_lock, 1.99, 0.01, "s", "docs/models/lugre_friction.md §7"))
    tr = run_of(result, STEP_RELEASE)
    if tr is not None:
        out += [Check("smin-step", "min slip, torque held to 2.6 s then released in one step (PDE)", _min_slip(tr)[0],
                      -0.1796, 3e-4, "-", "docs/models/lugre_friction.md §7"),
                Check("v3-step", "vehicle speed at 3 s, step release", float(np.interp(3.0, tr.t, tr.y[:, 0])), 3.05,
                      0.01, "m/s", "docs/models/lugre_friction.md §7")]
    return out


def _ol_checks(result, refs: dict, fig: str):
    """Checks of the open-loop model errors on braking #2 (T_max = 1000 N m)."""
    out = []
    src = f"docs/models/lugre_friction.md §7, §10 (FM {fig})"
    drv = BRAKINGS[1]
    if run_of(result, drv) is None:
        return out
    for case in open_loop_of(result, drv):
        tag = variant_tag(case)
        if tag not in refs:
            continue
        e = open_loop_errors(result, drv, case)
        ref_max, ref_rms, tol_max, tol_rms = refs[tag]
        out += [Check(f"maxdmu-k{tag}", f"max |mu - mu_PDE|, lumped kappa0 = {tag}, open loop, braking #2", e["max"],
                      ref_max, tol_max, "-", src),
                Check(f"rms100-k{tag}", f"RMS of mu - mu_PDE at 100 Hz, lumped kappa0 = {tag}", e["rms100"], ref_rms,
                      tol_rms, "-", src)]
    return out


def fig7_checks(result):
    return _ol_checks(result, {"1": (0.212, 0.124, 0.002, 0.002), "2": (0.131, 0.061, 0.002, 0.002)}, "Fig. 7")


def fig8_checks(result):
    out = _ol_checks(result, {"Z": (0.017, 0.0020, 0.001, 0.0005)}, "Fig. 8")
    drv = BRAKINGS[1]
    for case in open_loop_of(result, drv):
        if variant_tag(case) == "Z":
            out.append(Check("max100-kZ", "max |mu - mu_PDE| at the 100 Hz samples, kappa0(Z)",
                             open_loop_errors(result, drv, case)["max100"], 0.009, 0.001, "-", "docs/models/lugre_friction.md §10 (FM Fig. 8)"))
    pde, lum = run_of(result, drv), run_of(result, LUMPED_Z_COUPLED)
    if pde is not None and lum is not None:
        t = pde.t
        dmu = np.abs(np.interp(t, lum.t, lum.out["mu"]) - pde.out["mu"]).max()
        ds = np.abs(np.interp(t, lum.t, lum.out["slip"]) - pde.out["slip"]).max()
        out += [Check("coupled-dmu", "coupled quarter car: max |mu_lumped(Z) - mu_PDE|", float(dmu), 0.0046, 0.0005, "-",
                      "docs/models/lugre_friction.md §7"),
                Check("coupled-ds", "coupled quarter car: max |s_lumped(Z) - s_PDE|", float(ds), 0.0009, 0.0002, "-",
                      "docs/models/lugre_friction.md §7")]
    return out
