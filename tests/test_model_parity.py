"""Parity of every fast kernel with the model right-hand side it inlines (ARCHITECTURE.md "One model shape").

Each kernel of tirecli.numerics (and the exact steps of tirecli.models) re-derives its model's equations
for speed; here it is evaluated beside the model's ``rhs(t, x, u, p)`` / ``outputs(t, x, u, p)`` on random
states and inputs that cover its branches, and the largest absolute difference must be at most 1e-12 in
the units of each quantity scaled by its size: ``|a - b| <= 1e-12 max(1, |b|, S)`` (the wheel acceleration
reaches 1e4 rad/s^2, where one rounding is 2e-12), with ``S`` the size of the terms the model's form sums
where they cancel (the observer's slow manifold: terms of 1e5 rad/s^2 summing to about 1).
A kernel perturbed by 1e-11 (relative) in one term fails these tests.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from tirecli.models import lugre_lumped, quarter_car
from tirecli.models.lugre_lumped import LumpedTire
from tirecli.models.quarter_car import QuarterCar

TOL = 1e-12


def gap(a, b, scale=1.0) -> float:
    """Largest ``|a - b| / max(scale, |b|)`` (NaN anywhere but in both: inf)."""
    a, b = np.broadcast_arrays(np.asarray(a, dtype=float), np.asarray(b, dtype=float))
    if not np.array_equal(np.isnan(a), np.isnan(b)):
        return float("inf")
    ok = ~np.isnan(b)
    return float(np.max(np.abs(a[ok] - b[ok]) / np.maximum(max(scale, 1.0), np.abs(b[ok])), initial=0.0))


@pytest.fixture(scope="module")
def car():
    from tirecli.parameters.sets import load_builtin

    return load_builtin("canudas2003-obs-quarter-car").model()


@pytest.fixture(scope="module")
def tires():
    """Table 2 with the Stribeck exponents of the kernels' branches (1, 2 and any other)."""
    from tirecli.parameters.sets import load_builtin

    p = load_builtin("canudas2003-table2").model()
    return [p, replace(p, alpha=2.0), replace(p, alpha=0.7, sigma1=3.0)]


def states(car, n: int, seed: int):
    """Random quarter-car kinematics ``(v [m/s], omega [rad/s], theta [-], torque [N m])`` covering the branches:
    braking and driving slip, ``vr = 0`` exactly, the locked wheel (``omega = 0``), a wheel at standstill with the
    vehicle moving slowly, tiny and huge ``x = L/Z`` (``kappa0(Z)`` series and limit)."""
    rng = np.random.default_rng(seed)
    v = rng.uniform(0.5, 40.0, n)
    s = rng.uniform(-1.0, 0.6, n)
    omega = v * (1.0 + s) / car.r
    omega[::7] = 0.0                                   # locked wheel
    omega[1::7] = v[1::7] / car.r                      # vr = 0
    omega[2::7] = (v[2::7] + 1e-9) / car.r             # x = L/Z below the series threshold
    omega[3::7] = 1e-13 / car.r                        # x = L/Z above 1e12
    theta = rng.uniform(0.3, 1.6, n)
    torque = rng.uniform(-2500.0, 1200.0, n)
    return v, omega, theta, torque


def deflections(p, vr, theta, rng):
    """Bristle deflections [m] around their sliding values ``vr/b``, both signs."""
    from tirecli.models.lugre import stribeck

    zs = np.sign(vr) * stribeck(vr, p, theta) / p.sigma0
    return zs * rng.uniform(-1.5, 1.5, np.shape(vr))


# --------------------------------------------------------------------------- lumped tire, quarter car


def _lumped_stepper(p, car, kappa0, u, theta, v=None, omega=None):
    from tirecli.numerics.lumped import LumpedStepper

    return LumpedStepper(p, car, kappa0, lambda t: u[int(t)], lambda t: theta[int(t)],
                         None if v is None else (lambda t: v[int(t)]), None if omega is None else (lambda t: omega[int(t)]))


@pytest.mark.parametrize("kappa0", [1.0, 2.0, "Z"])
def test_lumped_stepper_is_the_quarter_car_rhs(tires, car, kappa0):
    """numerics.lumped.LumpedStepper (scalar right-hand side and outputs, free and locked wheel, and the tire
    alone with prescribed kinematics) against models.quarter_car.rhs/outputs and models.lugre_lumped.rhs."""
    from tirecli.numerics.ros2 import FREE, LOCKED, PRESCRIBED

    worst = {}
    for k, p in enumerate(tires):
        v, omega, theta, u = states(car, 70, k)
        z = deflections(p, car.r * omega - v, theta, np.random.default_rng(10 + k))
        qc = QuarterCar(LumpedTire(p, kappa0), car)
        st = _lumped_stepper(p, car, kappa0, u, theta)
        ps = _lumped_stepper(p, car, kappa0, u, theta, v, omega)
        names = st.out_names
        for i in range(len(v)):
            t, y = float(i), [v[i], omega[i], z[i]]
            ref = quarter_car.rhs(t, y, (u[i], theta[i]), qc)
            out = quarter_car.outputs(t, y, (u[i], theta[i]), qc)
            mode = LOCKED if omega[i] == 0.0 else FREE
            if mode == LOCKED:
                ref[1] = 0.0                            # the integrator holds omega = 0
            worst["rhs"] = max(worst.get("rhs", 0.0), gap(st.rhs_at(t, y, mode), ref))
            got = dict(zip(names, st.evaluate(t, y, mode)[1]))
            want = {"vr": out["vr"], "mu": out["mu"], "zdot": out["zdot"], "dv": ref[0], "domega": ref[1],
                    "kappa0": out["kappa0"]}
            worst["outputs"] = max(worst.get("outputs", 0.0), gap([got[n] for n in want], list(want.values())))
            # the tire alone: v, omega prescribed, (0, 0, dz/dt)
            tire = lugre_lumped.rhs(t, [z[i]], (car.r * omega[i] - v[i], car.r * omega[i], theta[i]), qc.tire)
            worst["prescribed"] = max(worst.get("prescribed", 0.0),
                                      gap(ps.rhs_at(t, [0.0, 0.0, z[i]], PRESCRIBED), [0.0, 0.0, tire[0]]))
    assert max(worst.values()) <= TOL, worst


@pytest.mark.parametrize("kappa0", [1.0, 2.0, "Z"])
def test_lumped_dense_output_is_the_quarter_car_rhs(tires, car, kappa0):
    """The vectorised arithmetic of LumpedStepper's dense output: the outputs it returns at the end of each
    step (state ``Y``, inputs at ``t0 + dt``) against models.quarter_car.rhs/outputs there."""
    from tirecli.numerics.ros2 import FREE, LOCKED

    for k, p in enumerate(tires):
        v, omega, theta, u = states(car, 60, 20 + k)
        z = deflections(p, car.r * omega - v, theta, np.random.default_rng(30 + k))
        th, tq = float(theta[0]), float(u[0])
        st = _lumped_stepper(p, car, kappa0, [tq] * 2, [th] * 2)
        modes = np.where(omega == 0.0, LOCKED, FREE)
        Y, O = st.dense(np.zeros(len(v)), np.column_stack([v, omega, z]), modes, np.full(len(v), 1e-7))
        o = dict(zip(st.out_names, O.T))
        qc = QuarterCar(LumpedTire(p, kappa0), car)
        ref = quarter_car.rhs(0.5, Y.T, (tq, th), qc)
        out = quarter_car.outputs(0.5, Y.T, (tq, th), qc)
        ref[1][modes == LOCKED] = 0.0
        pairs = [(o["dv"], ref[0]), (o["domega"], ref[1]), (o["zdot"], ref[2]), (o["vr"], out["vr"]),
                 (o["mu"], out["mu"]), (o["kappa0"], out["kappa0"])]
        worst = max(gap(a, b) for a, b in pairs)
        assert worst <= TOL, (k, worst)


# --------------------------------------------------------------------------- distributed tire


LOADS = {"uniform": ("uniform",), "exponential": ("exponential", 1.5), "parabolic": ("parabolic",),
         "tabulated": ("tabulated", 0.0, (0.0, 0.3, 0.6, 1.0), (0.2, 1.0, 0.7, 0.1))}


def _reduction(load):
    from tirecli.models.lugre_pde import patch_reduction

    return patch_reduction(*LOADS[load])


@pytest.mark.parametrize("load", list(LOADS))
def test_characteristics_stepper_is_the_quarter_car_rhs(tires, car, load):
    """numerics.characteristics.CharacteristicsStepper (``_eval1`` for one tire state, ``_eval`` for several; free,
    locked and prescribed) against models.quarter_car.rhs/outputs with the distributed tire and
    models.lugre_pde.rhs, the tracked deflections read from the stepper's own characteristic history."""
    from tirecli.models import lugre_pde
    from tirecli.models.lugre_pde import DistributedTire
    from tirecli.numerics.characteristics import CharacteristicsStepper
    from tirecli.numerics.ros2 import FREE, LOCKED, PRESCRIBED, integrate

    red = _reduction(load)
    worst = {}
    for k, p in enumerate(tires):
        v, omega, theta, u = states(car, 50, 40 + k)
        t_run = 0.3
        tq = {float(t_run + 1 + i): x for i, x in enumerate(u)}
        th = {float(t_run + 1 + i): x for i, x in enumerate(theta)}
        V = {float(t_run + 1 + i): x for i, x in enumerate(v)}
        W = {float(t_run + 1 + i): x for i, x in enumerate(omega)}

        def torque(t):
            return tq[t] if t > t_run else -800.0 * t / t_run

        def adhesion(t):
            return th[t] if t > t_run else 1.0
        st = CharacteristicsStepper(p, car, red, torque, adhesion, lambda t: V[t], lambda t: W[t])
        integrate(st, [20.0, 20.0 / car.r] + [0.0] * (3 + red.size), 0.0, t_run, tol=1e-5)   # a history
        hist = st.hist
        model = DistributedTire(p, red)
        qc = QuarterCar(model, car)
        rng = np.random.default_rng(50 + k)
        assert (st._eval == st._eval1) == (red.size == 1 and len(red.points) == 1)
        for i in range(len(v)):
            t = float(t_run + 1 + i)
            vr, romega = car.r * omega[i] - v[i], car.r * omega[i]
            Y = float(deflections(p, vr, theta[i], rng))
            x = [Y, hist.Phi[-1] + rng.uniform(-2.0, 40.0), rng.uniform(-0.1, 1.3) * hist.X[-1]]
            x += list(Y * red.A * rng.uniform(0.5, 1.5, red.size))
            # the tracked deflections z(u_i L) = Y - exp(Phi(tau) - Phi) Y(tau) from the stepper's history,
            # the current point (rates from the model) closing it
            dY, b, c = lugre_pde.rhs(t, x, (vr, romega, theta[i], np.zeros(len(red.points))), model)[:3]
            zp = []
            for d in red.points * p.L:
                Pt, Yt, _ = hist.lookup(x[2] - d, (t, x[2], x[1], Y, c, b, dY))
                zp.append(Y - np.exp(min(Pt - x[1], 0.0)) * Yt)
            y = [v[i], omega[i]] + x
            mode = LOCKED if omega[i] == 0.0 else FREE
            ref = quarter_car.rhs(t, y, (u[i], theta[i], zp), qc)
            out = quarter_car.outputs(t, y, (u[i], theta[i], zp), qc)
            if mode == LOCKED:
                ref[1] = 0.0
            worst["rhs"] = max(worst.get("rhs", 0.0), gap(st.rhs_at(t, y, mode), ref))
            got = dict(zip(st.out_names, st.evaluate(t, y, mode)[1]))
            want = {"vr": out["vr"], "mu": out["mu"], "zbar": out["zbar"], "zdot": out["zdot"], "dv": ref[0],
                    "domega": ref[1], "z_trailing": out["z_trailing"], "kappa0": out["kappa0"]}
            worst["outputs"] = max(worst.get("outputs", 0.0), gap([got[n] for n in want], list(want.values())))
            tire = lugre_pde.rhs(t, x, (vr, romega, theta[i], zp), model)
            worst["prescribed"] = max(worst.get("prescribed", 0.0),
                                      gap(st.rhs_at(t, [0.0, 0.0] + x, PRESCRIBED), [0.0, 0.0, *tire]))
    assert max(worst.values()) <= TOL, worst


@pytest.mark.parametrize("load", list(LOADS))
def test_driven_grid_is_the_distributed_tire_rhs(tires, load):
    """numerics.driven.GridModel (exponential integrator over time, two parameter sets at once) against
    models.lugre_pde.rhs at every grid node, the tracked deflections from the grid's own characteristics."""
    from tirecli.models import lugre_pde
    from tirecli.models.lugre_pde import DistributedTire
    from tirecli.numerics.driven import GridModel, drive_from_samples

    red = _reduction(load)
    t = np.linspace(0.0, 1.0, 101)
    v = 20.0 - 12.0 * t
    romega = v * (1.0 + 0.3 * np.sin(9.0 * t) - 0.1)    # braking and driving slip
    romega[60:70] = 0.0                                   # locked wheel
    drive = drive_from_samples(t, v, romega, 4, "linear")
    grid = GridModel(drive, tires[0].L, red)
    ps = [tires[0], replace(tires[2], sigma0=250.0, mu_s=1.1)]
    theta = 0.8
    sol = grid.solve(*(np.array([getattr(p, k) for p in ps]) for k in ("sigma0", "mu_c", "mu_s", "v_s", "alpha")),
                     theta=theta)
    worst = 0.0
    for i, p in enumerate(ps):
        x = np.vstack([sol["Y"][i], sol["Phi"][i], drive.X] + [s_[i] for s_ in sol["S"]])
        u = (drive.vr, drive.romega, theta, np.vstack([z[i] for z in sol["z_points"]]))
        got = np.vstack([sol["dY"][i], sol["b"][i], np.abs(drive.romega)] + [d[i] for d in sol["dS"]])
        worst = max(worst, gap(got, lugre_pde.rhs(drive.t, x, u, DistributedTire(p, red))))
        out = lugre_pde.outputs(drive.t, x, u, DistributedTire(p, red))
        worst = max(worst, gap(sol["zbar"][i], out["zbar"]), gap(sol["zdot"][i], out["zdot"]))
    assert worst <= TOL


# --------------------------------------------------------------------------- observer plant and observer


@pytest.fixture(scope="module")
def observers():
    """The OBS design plant (Stribeck exponent 1 and not 1) with the OBS gains, stiff gains (k1 = 1e6) and
    the theta-known gains (gamma = 0)."""
    from tirecli.observers import lugre_observer as lo
    from tirecli.parameters.sets import load_builtin

    tire = load_builtin("canudas2003-table1").model()
    car = load_builtin("canudas2003-obs-quarter-car").model()
    g = load_builtin("canudas2003-obs-gains").model()
    plants = [lo.ObserverPlant(tire, car), lo.ObserverPlant(replace(tire, alpha=1.6), car)]
    return [(pl, gg) for pl in plants for gg in (g, g.replace(k1=1.0e6), g.replace(gamma=0.0))]


def _observer_points(plant, n, seed):
    """Random plant states, estimates and inputs around a braking or driving wheel."""
    rng = np.random.default_rng(seed)
    v = rng.uniform(2.0, 35.0, n)
    w = v * (1.0 + rng.uniform(-0.6, 0.4, n)) / plant.car.r
    w[::5] = 0.0
    th_fm = rng.uniform(0.4, 1.5, n)
    z = deflections(plant.tire, plant.car.r * w - v, th_fm, rng)
    est = (v + rng.normal(0.0, 1.0, n), z * rng.uniform(0.5, 1.5, n), rng.uniform(0.3, 2.5, n))
    return v, w, z, th_fm, rng.uniform(-1500.0, 800.0, n), est, w + rng.normal(0.0, 0.5, n)


@pytest.mark.parametrize("encoder", [False, True])
def test_observer_scalar_rhs_is_the_models(observers, encoder):
    """numerics.observer.adaptive.scalar_rhs (what the adaptive methods integrate) against
    numerics.observer.reference.full_rhs, the composition of models.quarter_car.rhs and observers.observer.rhs:
    ideal and held measurement, with and without the encoder's wheel-angle state, for every gain variant."""
    from tirecli.numerics.observer.adaptive import scalar_rhs
    from tirecli.numerics.observer.reference import full_rhs
    from tirecli.numerics.observer.scenario import Scenario

    worst = 0.0
    for k, (plant, gains) in enumerate(observers):
        v, w, z, th_fm, u, (vh, zh, thh), y_held = _observer_points(plant, 40, 60 + k)
        c = plant.car
        tq = {float(i): x for i, x in enumerate(u)}
        th = {float(i): x for i, x in enumerate(th_fm)}
        sc = Scenario(duration=1.0, torque=lambda t: tq[t], theta_fm=lambda t: th[t], v0=20.0, omega0=60.0)
        fast, ref = scalar_rhs(plant, gains, sc), full_rhs(plant, gains, sc)
        for i in range(len(v)):
            X = [v[i], w[i], z[i], c.r * c.m * vh[i] + c.J * w[i], c.J * w[i] + plant.P * zh[i], zh[i], thh[i]]
            X = np.array(X + ([17.0] if encoder else []))
            for y in (None, y_held[i]):
                worst = max(worst, gap(fast(float(i), X, y), ref(float(i), X, y)))
    assert worst <= TOL, worst


def test_observer_fast_scheme_is_the_models(observers):
    """numerics.observer.fast.fast_model (the functions and constants simulate_fast inlines) against
    observers.plant.rhs and observers.observer.rhs: the plant's eta' and its stiff (chi, z) block, its wheel
    acceleration, and the observer's output error on its slow manifold (C x_hat' = y_m'), ideal and sampled."""
    from tirecli.numerics.observer.fast import fast_model
    from tirecli.observers import observer, plant as plant_model

    worst = {}
    for k, (pl, gains) in enumerate(observers):
        fm = fast_model(pl, gains)
        obs = observer.Observer(pl, gains)
        C = pl.matrices()[4]
        v, w, z, th_fm, u, (vh, zh_, thh), y_held = _observer_points(pl, 40, 80 + k)
        for i in range(len(v)):
            th = 1.0 / th_fm[i]
            x = np.array(pl.to_obs_coords(v[i], w[i], z[i]))
            dx = plant_model.rhs(0.0, x, (u[i], th), pl)
            vr = pl.car.r * w[i] - v[i]
            a = th * fm.aphi_of(vr) + fm.kr * abs(w[i])
            eta, chi = x[0], x[1]
            block = [-fm.c * eta + fm.E1 * w[i] + u[i], fm.m11 * chi + fm.m12 * z[i] + u[i],
                     fm.m21 * chi + (fm.m22c - a) * z[i] - eta * fm.irm]
            worst["plant"] = max(worst.get("plant", 0.0), gap(block, dx))
            yd = C @ dx
            qc = QuarterCar(LumpedTire(pl.tire), pl.car, sigma2_in_wheel=False)      # omega' without C x' cancelling
            dw = quarter_car.rhs(0.0, [v[i], w[i], z[i]], (u[i], th_fm[i]), qc)[1]
            worst["ydot"] = max(worst.get("ydot", 0.0), gap(fm.ydot(z[i], w[i], vr, a, u[i]), dw))
            # the observer on its slow manifold: estimates from the errors (eta~, chi~), measured y_m
            for ym, ydiff in ((w[i], 0.0), (y_held[i], -yd)):       # ideal; held sample (y_m' = 0)
                nv = ym - w[i]
                et = pl.car.r * pl.car.m * (v[i] - vh[i])
                ct = pl.P * (z[i] - zh_[i])
                yt, phh, zh, vhat = fm.oeval(et, ct, thh[i], eta, z[i], w[i], th * fm.aphi_of(vr) * z[i], nv, ydiff)
                xh = np.array([eta - et, chi - ct, zh, thh[i]])
                out = observer.outputs(0.0, xh, (ym, u[i]), obs)
                F0 = observer.rhs(0.0, xh, (ym, u[i]), obs)
                lam = pl.fast_rate(gains, thh[i])
                # y~ lam = y_m' - C F0, F0 the observer's rhs without injection: C F0 = C x_hat' - lam y~(x_hat)
                # (y~(x_hat) is 0 up to rounding); terms of P/J (|eta_hat|/(r m) + |E_3 y_m|) cancel in C F0
                terms = pl.P / pl.car.J * (abs(xh[0]) * fm.irm + abs(pl.E[2] * ym))
                worst["slow manifold"] = max(worst.get("slow manifold", 0.0),
                                             gap(yt * lam, ydiff + yd - (C @ F0[:3] - lam * out["y_tilde"]), terms),
                                             gap(out["y_tilde"], 0.0 * ym), gap(vhat, out["v_hat"]),
                                             gap(phh, pl.phi(ym, xh[0], zh)))
    assert max(worst.values()) <= TOL, worst


# --------------------------------------------------------------------------- MCPS law and belt


@pytest.fixture(scope="module")
def mcps():
    from tirecli.parameters.sets import load_builtin

    return load_builtin("sorine2000-mcps").model()


@pytest.fixture(scope="module")
def laws(mcps):
    """The patch law (per unit length) and the slider law of the built-in set (second order), and a first-order law."""
    from tirecli.models.mcps import law as L

    return [mcps.patch_law(4000.0), mcps.slider_law(mcps.patch(4000.0).P),
            L.first_order([5000.0, 3500.0], [19.8, 18.7], 0.35, 0.187)]


def exact_flow(law, x0, u):
    """The exact flow over a unit time of models.mcps.law.rhs with the constant input ``u`` (rate independence:
    ``u`` the increments): ``x0 + phi_1(A) f(x0)`` for the affine right-hand side ``f(x) = A x + b``, ``phi_1`` from
    the matrix exponential (scipy) of ``[[A, f(x0)/s], [0, 0]]`` (``s = max |f(x0)|``: a norm of the size of ``A``)."""
    from scipy.linalg import expm

    from tirecli.models.mcps import law as L

    n = len(x0)
    b = L.rhs(0.0, np.zeros(n), u, law)
    big = 2.0 ** 30          # columns of A from far-apart points: b (up to 1e5) does not swamp them
    A = np.column_stack([(L.rhs(0.0, big * e, u, law) - b) / big for e in np.eye(n)])
    r = L.rhs(0.0, x0, u, law)
    s = max(float(np.max(np.abs(r))), 1e-300)
    M = np.zeros((n + 1, n + 1))
    M[:n, :n], M[:n, n] = A, r / s
    return x0 + s * expm(M)[:n, n]


def _law_points(law, rng, n):
    """Random law states near the Coulomb levels, increments from 1e-6 to 10 patch relaxations, spins, frame turns
    (0 in a third of them)."""
    F = rng.normal(size=(n, law.nb, 2)) * law.Fk
    M = rng.normal(size=(n, law.nbz)) * law.Mkz
    scale = 10.0 ** rng.uniform(-6, 1, (n, 1)) * law.Fk / law.K
    du = rng.normal(size=(n, 2)) * scale
    dpsi = rng.normal(size=n) * 10.0 ** rng.uniform(-4, 0, n)
    dth = np.where(np.arange(n) % 3 == 0, 0.0, rng.normal(size=n) * 10.0 ** rng.uniform(-4, 0, n))
    du[n // 2] = 0.0                                   # at rest
    return F, M, du, dpsi, dth


def test_mcps_law_step_is_the_exact_flow_of_the_rhs(laws):
    """models.mcps.law.step (closed-form 2 x 2 exponential per branch) against the exact flow of models.mcps.law.rhs
    (matrix exponential of the whole state), outputs through models.mcps.law.outputs."""
    from tirecli.models.mcps import law as L

    worst = 0.0
    for k, law in enumerate(laws):
        F, M, du, dpsi, dth = _law_points(law, np.random.default_rng(90 + k), 40)
        F1, M1 = L.step(F, M, du, dpsi, dth, law)
        for i in range(len(F)):
            u = (du[i, 0], du[i, 1], dpsi[i], dth[i])
            ref = exact_flow(law, L.join_state(F[i], M[i]), u)
            worst = max(worst, gap(L.join_state(F1[i], M1[i]), ref))
            f, m = L.output(F1[i], M1[i], law)
            o = L.outputs(0.0, ref, u, law)
            worst = max(worst, gap([*f, m], [o["f_x"], o["f_y"], o["m"]]))
    assert worst <= TOL, worst


def test_mcps_rolling_patch_step_is_the_law(mcps):
    """numerics.mcps_transient.patch_step (every tread element of the rolling tire, exact per component, the frame
    rotation split half a step before and after) against the exact flows of models.mcps.law.rhs: the law without
    its frame term, between two half turns of the frame term alone."""
    from tirecli.models.mcps import law as L
    from tirecli.numerics.mcps_transient import patch_step

    law = mcps.patch_law(4000.0)
    G = np.concatenate([law.g.T, law.gz[None, :]])[:, :, None]
    H = np.concatenate([law.h.T, law.hz[None, :]])[:, :, None]
    rng = np.random.default_rng(7)
    N = 30
    worst = 0.0
    for dth in (0.0, 3e-3, -0.2):
        F, M, du2, _, _ = _law_points(law, rng, N)
        dps = 0.5 * dth if dth else 1e-3
        S0 = np.concatenate([np.moveaxis(F, 0, -1).transpose(1, 0, 2), np.moveaxis(M, 0, -1)[None]])  # (3, nb, N)
        du = np.concatenate([du2.T[:, None, :], np.full((1, 1, N), dps)])
        S1 = patch_step(S0, du, dth, -G, H, law.Fk, np.empty((3, 1, N)), np.empty((3, law.nb, N)))
        for e in range(N):
            x = L.join_state(F[e], M[e])
            x = exact_flow(law, x, (0.0, 0.0, 0.0, 0.5 * dth))
            x = exact_flow(law, x, (du2[e, 0], du2[e, 1], dps, 0.0))
            x = exact_flow(law, x, (0.0, 0.0, 0.0, 0.5 * dth))
            worst = max(worst, gap(L.join_state(S1[:2, :, e].T, S1[2, :, e]), x))
    assert worst <= TOL, worst


def test_mcps_stationary_rates_are_the_law(laws):
    """models.mcps.tire.stationary_rates (the RK4 kernel of the stationary patch with a yaw rate) against
    models.mcps.law.rhs per unit rolled distance."""
    from tirecli.models.mcps import law as L
    from tirecli.models.mcps.tire import stationary_rates

    law, l = laws[0], 0.15
    rng = np.random.default_rng(8)
    P = 25
    F = rng.normal(size=(P, law.nb, 2)) * law.Fk
    sx, sy0, phi = rng.normal(size=P) * 0.1, rng.normal(size=P) * 0.1, rng.normal(size=P) * 2.0
    d = rng.uniform(0.0, l, P)
    worst = 0.0
    for frame in (False, True):
        got = stationary_rates(d, F, sx, sy0, phi, law, l, frame)
        u = (sx, sy0 + phi * (l / 2.0 - d), phi, phi if frame else 0.0)
        ref = L.rhs(0.0, L.join_state(F, np.zeros((P, law.nbz))), u, law)[:2 * law.nb]
        worst = max(worst, gap(L.join_state(got, np.zeros((P, 0))), ref))
    assert worst <= TOL, worst


@pytest.mark.parametrize("locked", [(), (2,), (0, 1)])
def test_mcps_belt_step_is_the_trapezoidal_rule_of_the_belt_rhs(mcps, locked):
    """numerics.mcps_transient._belt_matrices: ``y1 = Phi y0 + Gam (u0 + u1)`` is the trapezoidal rule of
    models.mcps.belt.rhs, ``(y1 - y0)/dt = (f(y0, u0) + f(y1, u1))/2``, with the locked DOFs held at zero;
    the rim forces of models.mcps.belt.outputs are ``k q + c qdot`` with the kernel's ``k``, ``c``."""
    from tirecli.models.mcps import belt
    from tirecli.numerics.mcps_transient import _belt_matrices

    dt = 1e-4
    Phi, Gam, kv, cv = _belt_matrices(mcps, dt, locked)
    rng = np.random.default_rng(9)
    worst = 0.0
    for _ in range(20):
        y0 = rng.normal(size=6) * [1e-3, 1e-3, 1e-2, 0.1, 0.1, 1.0]
        for j in locked:
            y0[[j, 3 + j]] = 0.0
        u0, u1 = (rng.normal(size=3) * [300.0, 300.0, 30.0] for _ in range(2))
        y1 = Phi @ y0 + Gam @ (u0 + u1)
        mean = 0.5 * (belt.rhs(0.0, y0, u0, mcps) + belt.rhs(0.0, y1, u1, mcps))
        free = [j for j in range(6) if j % 3 not in locked]
        worst = max(worst, gap(((y1 - y0) / dt)[free], mean[free]))
        assert all(y1[j] == 0.0 and y1[3 + j] == 0.0 for j in locked)
        o = belt.outputs(0.0, y1, u1, mcps)
        worst = max(worst, gap(kv * y1[:3] + cv * y1[3:], [o["rim_fx"], o["rim_fy"], o["rim_mz"]]))
    assert worst <= TOL, worst
