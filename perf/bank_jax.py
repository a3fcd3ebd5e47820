#!/usr/bin/env python3
"""The filter bank of `kushner filter --model sine --filters EKF,SOF,QLF,KBL` in JAX (issue 16 part 4's GPU
comparison): arrays over members, the step loop as one `lax.scan`, fp64, the equations of perf/bank_numpy.py
(truth by Euler-Maruyama, then every filter's update and prediction with the truth's dy), normals from
jax.random drawn inside the scan (one key split per step), no metrics. Compilation is excluded: each T is run once
to compile, then timed with block_until_ready.

With --metrics the bank also does, in JAX, what `kushner filter`'s bank does besides the filters' equations: a
member's filter that turns non-finite or not positive definite is frozen with its status (as is a truth that turns
non-finite), each step adds every member's squared error and NEES to its score sums, and every step is an output step
(as for `kushner filter` at T <= 0.25 with its default 200 output points: a point per step), at which the squared
errors' and the NEES' ensemble means and sums of squared deviations (two passes over the finite values) and the
filters' divergence counts are taken, their rows stacked by the scan: the command line's work, without its files.

usage: bank_jax.py [--members M] [--T T] [--dt DT] [--rate T_SHORT] [--repetitions R] [--metrics]
Prints one JSON object: wall seconds of the step loop at T (and at T_SHORT), member-steps/s per repetition (from
the difference when --rate is given: perf/compare_bank_numpy.sh's method), the median, and the device.
"""
import argparse
import json
import statistics
import time

import jax

jax.config.update("jax_enable_x64", True)
import jax.numpy as jnp  # noqa: E402

Q, R = 1.0, 0.5


def make_run(members, steps, dt, metrics=False):
    sq, V, W = dt**0.5, R * R, Q * Q * dt
    kinds = ("EKF", "SOF", "QLF", "KBL")

    def update_predict(m, P, dy, kind):
        K = P / (V + P * dt)
        m = m + K * (dy - m * dt)
        P = P - K * P * dt
        if kind == "KBL":
            return m * (1.0 - dt), P * (1.0 - dt) ** 2 + W
        s, c = jnp.sin(m), jnp.cos(m)
        if kind == "EKF":
            a, J = -s, -c
        elif kind == "SOF":
            a, J = -s + 0.5 * s * P, -c
        else:  # QLF
            damping = jnp.exp(-0.5 * P)
            a, J = -s * damping, -c * damping
        return m + a * dt, (1.0 + J * dt) ** 2 * P + W

    def truth(key, x):
        """The truth's Euler-Maruyama step and its observation increment: (key, x after the step, dy)."""
        key, k1, k2 = jax.random.split(key, 3)
        dw = jax.random.normal(k1, (members,), dtype=jnp.float64)
        dv = jax.random.normal(k2, (members,), dtype=jnp.float64)
        return key, x - jnp.sin(x) * dt + Q * sq * dw, x * dt + R * sq * dv

    def step(carry, _):
        key, x, ms, Ps = carry
        key, x, dy = truth(key, x)
        out = [update_predict(m, P, dy, kind) for m, P, kind in zip(ms, Ps, kinds)]
        return (key, x, tuple(o[0] for o in out), tuple(o[1] for o in out)), None

    def moments(columns):
        """Per row of `columns` (rows, members): the count, mean and sum of squared deviations of its finite values
        (two passes), all rows in one reduction each (a reduction per column ran the bank at half the rate)."""
        finite = jnp.isfinite(columns)
        count = finite.sum(axis=1, dtype=jnp.float64)
        mean = jnp.where(finite, columns, 0.0).sum(axis=1) / count
        d = jnp.where(finite, columns - mean[:, None], 0.0)
        return jnp.concatenate([count, mean, (d * d).sum(axis=1)])

    def scored_step(carry, _):
        key, x, live, filters = carry
        key, moved, dy = truth(key, x)
        live = live & jnp.isfinite(moved) & jnp.isfinite(dy)
        x = jnp.where(live, moved, x)
        stepped, snapshots, diverged = [], [], []
        for (m, P, ok, sums), kind in zip(filters, kinds):
            m1, P1 = update_predict(m, P, dy, kind)
            good = live & ok & jnp.isfinite(m1) & jnp.isfinite(P1) & (P1 > 0.0)
            ok = ok & (~live | good)
            se = (m1 - x) ** 2
            nees = jnp.where(good, se / P1, jnp.nan)
            sums = (sums[0] + jnp.where(good, se, 0.0), sums[1] + jnp.where(good, nees, 0.0),
                    sums[2] + jnp.where(good, 1.0, 0.0))
            stepped.append((jnp.where(good, m1, m), jnp.where(good, P1, P), ok, sums))
            snapshots += [jnp.where(good, se, jnp.nan), nees]
            diverged.append(live & ~ok)
        row = jnp.concatenate([moments(jnp.stack(snapshots)), jnp.stack(diverged).sum(axis=1, dtype=jnp.float64)])
        return (key, x, live, tuple(stepped)), row

    @jax.jit
    def run(key):
        key, k0 = jax.random.split(key)
        x = 1.0 + jax.random.normal(k0, (members,), dtype=jnp.float64)
        ones = jnp.ones(members, dtype=jnp.float64)
        if not metrics:
            carry, _ = jax.lax.scan(step, (key, x, (ones,) * 4, (ones,) * 4), None, length=steps)
            return carry[1], carry[2], carry[3]
        zeros, ok = jnp.zeros(members, dtype=jnp.float64), jnp.ones(members, dtype=bool)
        filters = tuple((ones, ones, ok, (zeros, zeros, zeros)) for _ in kinds)
        carry, rows = jax.lax.scan(scored_step, (key, x, ok, filters), None, length=steps)
        return carry[1], carry[3], rows

    return run


def timed(run, seed):
    out = run(jax.random.PRNGKey(seed))  # compile
    jax.block_until_ready(out)
    start = time.perf_counter()
    out = run(jax.random.PRNGKey(seed + 1))
    jax.block_until_ready(out)
    return time.perf_counter() - start


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--members", type=int, default=1000000)
    ap.add_argument("--T", type=float, default=0.25)
    ap.add_argument("--dt", type=float, default=1e-3)
    ap.add_argument("--rate", type=float, default=None)
    ap.add_argument("--repetitions", type=int, default=3)
    ap.add_argument("--metrics", action="store_true", help="statuses, score sums and every step's moments too")
    a = ap.parse_args()
    steps = round(a.T / a.dt)
    run_long = make_run(a.members, steps, a.dt, a.metrics)
    run_short = make_run(a.members, round(a.rate / a.dt), a.dt, a.metrics) if a.rate else None
    long_s, short_s, rates = [], [], []
    for rep in range(a.repetitions):
        long_s.append(timed(run_long, 2 * rep))
        if run_short:
            short_s.append(timed(run_short, 2 * rep))
            rates.append(a.members * (steps - round(a.rate / a.dt)) / (long_s[-1] - short_s[-1]))
        else:
            rates.append(a.members * steps / long_s[-1])
    print(json.dumps({"jax": jax.__version__, "device": str(jax.devices()[0]), "members": a.members, "T": a.T,
                      "dt": a.dt, "metrics": a.metrics, "step_loop_s": long_s, "step_loop_short_s": short_s,
                      "member_steps_per_s": rates, "median": statistics.median(rates)}))


if __name__ == "__main__":
    main()
