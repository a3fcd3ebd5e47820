#!/usr/bin/env python3
"""The filter bank of `kushner filter --model sine --filters EKF,SOF,QLF,KBL` written as a competent NumPy user
would: every member in one 1-D array, in-place ufuncs, one core, no metrics (unless --metrics).

Model (models/sine_model.hpp, seed 000 (6.1)-(6.3)): dx = -sin x dt + q dw, dy = x dt + r dv, q = 1, r = 0.5,
truths x(0) ~ N(1, 1), every filter's prior N(1, 1). Per step k, as kernels/simulate_truth.hpp and
kernels/filters/filter_bank_step.hpp do it:
  truth (Euler-Maruyama):  dy = x dt + r dv,  x <- x - sin(x) dt + q dw,   dw, dv ~ N(0, dt)
  every filter, with that dy (kernels/filters/filter_step.hpp):
    update:   S = r^2 + P dt,  K = P / S,  m <- m + K (dy - h dt),  P <- P - K P dt
    predict:  m <- m + a dt,   P <- (1 + J dt)^2 P + q^2 dt
  with, for the sine model (obs_dim = state_dim = 1, h(x) = x, so h = m for all four):
    EKF (extended_kalman_filter.hpp):          a = -sin m,                     J = -cos m        (at the updated m)
    SOF (second_order_filter.hpp):             a = -sin m + 1/2 sin(m) P,      J = -cos m        (h'' = 0: no dy term)
    QLF (quasi_linear_filter.hpp, closed form, seed 000 (6.4)-(6.5)):
                                               a = -sin(m) e^{-P/2},           J = -cos(m) e^{-P/2}
    KBL (linearized_kalman_bucy_filter.hpp):   a = -m,                         J = -1            (at the origin)
Timed, the bank draws from NumPy's default generator. With --philox it draws kushner's own numbers instead
(Philox4x32-10 keyed by {seed, stream}, counter {member, 0, step, 0}, 52-bit uniforms, Box-Muller: kernels/rng.hpp;
a truth's dv is the first normal of its step's block of the process-noise stream and dw the second), so it sees
the very noise `kushner filter --seed S` sees, and --check DIR (a kushner filter run's summary.json with
the same M, T, dt and seed) compares every filter's rmse_truth and nees: they agree to rounding (libm vs NumPy's
sin/cos/exp/log, and P / S vs kushner's P (1 / S)). --metrics computes kushner's rmse_truth (root of
the time-and-ensemble mean of (m - x)^2 over the time points 0, dt, ..., T, delta-method standard error) and nees.

usage: bank_numpy.py [--members M] [--T T] [--dt DT] [--seed S] [--repetitions R] [--metrics] [--philox]
                     [--check DIR] [--rate T_SHORT]
Prints one JSON object: the wall time of each repetition's step loop and member-steps/s; with --rate T_SHORT,
also the runs at T_SHORT and the rate from the difference (the method of perf/compare_bank_numpy.sh).
"""
import argparse
import json
import statistics
import time

import numpy as np

Q, R = 1.0, 0.5
FILTERS = ("EKF", "SOF", "QLF", "KBL")
TRUTH_INITIAL, PROCESS_NOISE = 1, 2  # kernels/rng.hpp's Stream values
MASK = np.uint64(0xFFFFFFFF)


def philox_normals(seed, stream, members, step):
    """kushner's two normals of block {member, 0, step, 0} of key {seed, stream} for every member."""
    c0 = np.arange(members, dtype=np.uint64)
    c1 = np.zeros(members, dtype=np.uint64)
    c2 = np.full(members, step, dtype=np.uint64)
    c3 = np.zeros(members, dtype=np.uint64)
    k0, k1 = np.uint64(seed), np.uint64(stream)
    for _ in range(10):
        p0 = np.uint64(0xD2511F53) * c0
        p1 = np.uint64(0xCD9E8D57) * c2
        c0, c1, c2, c3 = (p1 >> np.uint64(32)) ^ c1 ^ k0, p1 & MASK, (p0 >> np.uint64(32)) ^ c3 ^ k1, p0 & MASK
        k0 = (k0 + np.uint64(0x9E3779B9)) & MASK
        k1 = (k1 + np.uint64(0xBB67AE85)) & MASK
    def uniform(hi, lo):
        return ((((hi << np.uint64(32)) | lo) >> np.uint64(12)).astype(np.float64) + 0.5) * 2.0**-52
    u0, u1 = uniform(c0, c1), uniform(c2, c3)
    radius = np.sqrt(-2.0 * np.log(u0))
    return radius * np.cos(2.0 * np.pi * u1), radius * np.sin(2.0 * np.pi * u1)


def run_bank(members, T, dt, seed, metrics=False, philox=False):
    """Runs truths and the four filters over [0, T]; returns (seconds of the step loop, metrics or None)."""
    rng = np.random.default_rng(seed)
    steps = int(round(T / dt))
    sq = np.sqrt(dt)
    V, W = R * R, Q * Q * dt
    x = 1.0 + (philox_normals(seed, TRUTH_INITIAL, members, 0)[0] if philox else rng.standard_normal(members))
    m = {f: np.full(members, 1.0) for f in FILTERS}
    P = {f: np.full(members, 1.0) for f in FILTERS}
    dw, dv, dy = np.empty(members), np.empty(members), np.empty(members)
    s, c, k, t1, t2 = (np.empty(members) for _ in range(5))
    if metrics:
        sq_sum = {f: (m[f] - x) ** 2 for f in FILTERS}
        nees_sum = {f: (m[f] - x) ** 2 / P[f] for f in FILTERS}
    start = time.perf_counter()
    for step in range(steps):
        if philox:
            dv[:], dw[:] = philox_normals(seed, PROCESS_NOISE, members, step)
        else:
            rng.standard_normal(out=dw)
            rng.standard_normal(out=dv)
        # dy = x dt + r sqrt(dt) dv, then x <- x - sin(x) dt + q sqrt(dt) dw
        np.multiply(x, dt, out=dy)
        dv *= R * sq
        dy += dv
        np.sin(x, out=s)
        s *= dt
        x -= s
        dw *= Q * sq
        x += dw
        for f in FILTERS:
            mf, Pf = m[f], P[f]
            # update: K = P / (V + P dt), m += K (dy - m dt), P -= K P dt
            np.multiply(Pf, dt, out=t1)
            t1 += V
            np.divide(Pf, t1, out=k)
            np.multiply(mf, dt, out=t2)
            np.subtract(dy, t2, out=t2)
            t2 *= k
            mf += t2
            k *= Pf
            k *= dt
            Pf -= k
            # predict: m += a dt, P = (1 + J dt)^2 P + W
            if f == "KBL":
                mf *= 1.0 - dt
                Pf *= (1.0 - dt) ** 2
            else:
                np.sin(mf, out=s)
                np.cos(mf, out=c)
                if f == "EKF":
                    np.multiply(s, -dt, out=t1)  # a dt
                elif f == "SOF":
                    np.multiply(Pf, 0.5, out=t1)
                    t1 -= 1.0
                    t1 *= s
                    t1 *= dt
                else:  # QLF: damping e^{-P/2}
                    np.multiply(Pf, -0.5, out=t2)
                    np.exp(t2, out=t2)
                    s *= t2
                    c *= t2
                    np.multiply(s, -dt, out=t1)
                mf += t1
                c *= -dt
                c += 1.0
                c *= c
                Pf *= c
            Pf += W
        if metrics:
            for f in FILTERS:
                np.subtract(m[f], x, out=t1)
                t1 *= t1
                sq_sum[f] += t1
                t1 /= P[f]
                nees_sum[f] += t1
    seconds = time.perf_counter() - start
    if not metrics:
        return seconds, None
    points = steps + 1
    out = {}
    for f in FILTERS:
        per_member = sq_sum[f] / points
        mean, se = per_member.mean(), per_member.std(ddof=1) / np.sqrt(members)
        nees = nees_sum[f] / points
        out[f] = {"rmse_truth": float(np.sqrt(mean)), "rmse_truth_se": float(se / (2 * np.sqrt(mean))),
                  "nees": float(nees.mean()), "nees_se": float(nees.std(ddof=1) / np.sqrt(members))}
    return seconds, out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--members", type=int, default=1000000)
    ap.add_argument("--T", type=float, default=0.25)
    ap.add_argument("--dt", type=float, default=1e-3)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--repetitions", type=int, default=1)
    ap.add_argument("--rate", type=float, default=None, help="also run at this shorter T; rate from the difference")
    ap.add_argument("--metrics", action="store_true", help="score like kushner (rmse_truth, nees); not timed fairly")
    ap.add_argument("--philox", action="store_true", help="draw kushner's Philox numbers (for --check)")
    ap.add_argument("--check", default=None, help="kushner output directory (summary.json) to compare with")
    a = ap.parse_args()
    result = {"numpy": np.__version__, "members": a.members, "T": a.T, "dt": a.dt, "filters": list(FILTERS)}
    long_s, short_s, rates = [], [], []
    metrics = None
    for rep in range(a.repetitions):
        seconds, metrics = run_bank(a.members, a.T, a.dt, a.seed + rep, a.metrics or a.check is not None, a.philox)
        long_s.append(seconds)
        if a.rate is not None:
            short, _ = run_bank(a.members, a.rate, a.dt, a.seed + rep)
            short_s.append(short)
            steps = round(a.T / a.dt) - round(a.rate / a.dt)
            rates.append(a.members * steps / (seconds - short))
        else:
            rates.append(a.members * round(a.T / a.dt) / seconds)
    result["step_loop_s"] = long_s
    if short_s:
        result["step_loop_short_s"] = short_s
        result["T_short"] = a.rate
    result["member_steps_per_s"] = rates
    result["median"] = statistics.median(rates)
    result["min"], result["max"] = min(rates), max(rates)
    if metrics:
        result["metrics"] = metrics
    if a.check:
        summary = json.load(open(a.check + "/summary.json"))
        worst_z, worst_relative = 0.0, 0.0
        for f in FILTERS:
            k = summary["filters"][f]
            z = (metrics[f]["rmse_truth"] - k["rmse_truth"]) / np.hypot(metrics[f]["rmse_truth_se"], k["rmse_truth_se"])
            metrics[f]["kushner_rmse_truth"] = k["rmse_truth"]
            metrics[f]["kushner_nees"] = k["nees"]
            metrics[f]["z"] = float(z)
            worst_z = max(worst_z, abs(z))
            for key in ("rmse_truth", "nees"):
                worst_relative = max(worst_relative, abs(metrics[f][key] - k[key]) / abs(k[key]))
        result["check_worst_z"] = float(worst_z)
        result["check_worst_relative_difference"] = float(worst_relative)
    print(json.dumps(result))


if __name__ == "__main__":
    main()
