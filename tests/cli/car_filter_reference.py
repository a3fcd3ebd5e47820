#!/usr/bin/env python3
"""A second implementation of `kushner reproduce basin-car-filter` (seed 002, section 7), for the tests.

usage: car_filter_reference.py REPRODUCTION_CSV DT

Recomputes every number of the car example in plain Python with the engine's discretization (truth: Euler steps;
dy = x dt + (cos t - cos(t + dt)); filters: Kalman update with dy, then the prediction of
kernels/filters/filter_step.hpp) and the prior-line quadrature with numpy, and compares them with the
`ours` column of reproduction.csv. Exits 1 naming the first number that differs by more than 1e-9 relative.
"""
import csv
import math
import sys

V_OVER_L, U, T = 1.0, 0.05, 20.0


def mat_mul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(2)) for j in range(2)] for i in range(2)]


def transpose(a):
    return [[a[j][i] for j in range(2)] for i in range(2)]


def update(m, P, dy, dt):
    """Step 1 of filter_step.hpp with H = I, V = I: S = I + dt P, K = P S^-1, m += K (dy - m dt), P -= dt K P."""
    S = [[1.0 + dt * P[0][0], dt * P[0][1]], [dt * P[1][0], 1.0 + dt * P[1][1]]]
    det = S[0][0] * S[1][1] - S[0][1] * S[1][0]
    Sinv = [[S[1][1] / det, -S[0][1] / det], [-S[1][0] / det, S[0][0] / det]]
    K = mat_mul(P, Sinv)
    innovation = [dy[0] - m[0] * dt, dy[1] - m[1] * dt]
    m = [m[i] + K[i][0] * innovation[0] + K[i][1] * innovation[1] for i in range(2)]
    KP = mat_mul(K, transpose(P))
    P = [[P[i][j] - KP[i][j] * dt for j in range(2)] for i in range(2)]
    return m, P


def predict(m, P, a, J, dt):
    """Step 2: m += a dt, P <- (I + J dt) P (I + J dt)^T."""
    step = [[(1.0 if i == j else 0.0) + J[i][j] * dt for j in range(2)] for i in range(2)]
    return [m[0] + a[0] * dt, m[1] + a[1] * dt], mat_mul(mat_mul(step, P), transpose(step))


def run(system, dt):
    steps = round(T / dt)
    x = [0.0, 0.0]
    prior = ([10.0, 0.1], [[100.0, 10.0], [10.0, 1.0]])
    est = {name: (list(prior[0]), [row[:] for row in prior[1]]) for name in ("KBL", "POLY3", "POLY3-21")}
    dys = []
    for k in range(steps):
        t = k * dt
        noise = math.cos(t) - math.cos(t + dt)
        dy = [x[0] * dt + noise, x[1] * dt + noise]
        dys.append(dy)
        d = x[1]
        rate = V_OVER_L * (d + d ** 3 / 3.0) if system == "taylor" else V_OVER_L * math.tan(d)
        x = [x[0] + rate * dt, x[1] + U * dt]
        for name, (m, P) in est.items():
            m, P = update(m, P, dy, dt)
            md, pdd, pfd = m[1], P[1][1], P[0][1]
            if name == "KBL":  # (22): the model linearized at 0
                m, P = predict(m, P, [V_OVER_L * md, U], [[0.0, V_OVER_L], [0.0, 0.0]], dt)
            elif name == "POLY3":  # (9)-(10): E[x^3] = 3 p m + m^3, J = a1 + 3 a3 diag(p + m^2)
                a = [V_OVER_L * (md + (3.0 * pdd * md + md ** 3) / 3.0), U]
                m, P = predict(m, P, a, [[0.0, V_OVER_L * (1.0 + pdd + md * md)], [0.0, 0.0]], dt)
            else:  # (21) as printed
                a = [V_OVER_L * md + V_OVER_L / 3.0 * (3.0 * pdd + md ** 3), U]
                D = [[2 * V_OVER_L * (pfd * pdd + pfd + md * md * pfd), V_OVER_L * (pdd + md * md * pdd)], [0.0, 0.0]]
                D[1][0] = D[0][1]
                m = [m[0] + a[0] * dt, m[1] + a[1] * dt]
                P = [[P[i][j] + D[i][j] * dt for j in range(2)] for i in range(2)]
                P[0][1] = P[1][0] = 0.5 * (P[0][1] + P[1][0])
            est[name] = (m, P)
    values = {"phi": x[0], "delta": x[1]}
    for name, (m, _) in est.items():
        values[name + "/m_phi"], values[name + "/m_delta"] = m
    try:
        import numpy as np
    except ImportError:
        return values
    # Prior-line quadrature: x(0) = m0 + s v, v v^T = P(0), 4097 nodes on [-8, 8], Girsanov weights.
    evals, evecs = np.linalg.eigh(np.array(prior[1]))
    v = evecs[:, 1] * math.sqrt(evals[1])
    s = np.linspace(-8.0, 8.0, 4097)
    X = np.array(prior[0])[None, :] + s[:, None] * v[None, :]
    logw = -0.5 * s * s
    for k in range(steps):
        t = k * dt
        logw = logw + X @ np.array(dys[k]) - 0.5 * (X * X).sum(axis=1) * dt
        d = X[:, 1]
        X = X + np.stack([V_OVER_L * (d + d ** 3 / 3.0), np.full_like(d, U)], axis=1) * dt
    w = np.exp(logw - logw.max())
    mean = (w[:, None] * X).sum(axis=0) / w.sum()
    values["EXACT/m_phi"], values["EXACT/m_delta"] = float(mean[0]), float(mean[1])
    return values


def main():
    path, dt = sys.argv[1], float(sys.argv[2])
    with open(path) as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    ours = {r["key"]: float(r["ours"]) for r in rows}
    checked = 0
    for system in ("taylor", "tan"):
        values = run(system, dt)
        for key, value in values.items():
            names = [f"{system}/{c}/{key}" for c in ("KB", "POLY3")] if key in ("phi", "delta") else \
                [f"{system}/{key.replace('KBL', 'KB')}"]
            for name in names:
                if abs(ours[name] - value) > 1e-9 * max(1.0, abs(value)):
                    sys.exit(f"{name}: reproduction.csv has {ours[name]!r}, the Python reference {value!r}")
                checked += 1
    print(f"{checked} numbers agree with the Python reference to 1e-9")


if __name__ == "__main__":
    main()
