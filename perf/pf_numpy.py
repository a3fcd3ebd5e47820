#!/usr/bin/env python3
"""The particle-filter step of bench_particle_filter.cpp written as a competent NumPy user would: all
members and particles as one (M, N) array, in-place ufuncs, systematic resampling by cumsum + searchsorted
for the members whose ESS fell below N/2. Sine model dx = -sin x dt + q dw, dy = x dt + r dv, q = 1,
r = 0.5, prior N(1, 1), dt = 1e-3, fp64. Per step: propagate, weight, log-sum-exp normalization, posterior
mean and variance, ESS, resampling where needed -- the same work as BM_ParticleFilterStep.

usage: pf_numpy.py [--members M] [--particles N] [--steps K] [--repetitions R] [--seed S]
Prints one JSON object: particle_steps_per_s for every repetition, their median, and the spread.
NumPy's ufuncs run on one core.
"""
import argparse
import json
import statistics
import time

import numpy as np

Q, R, DT, M0, S0 = 1.0, 0.5, 1e-3, 1.0, 1.0


def simulate_observations(members, steps, rng):
    """Euler-Maruyama truths (as kernels/simulate_truth.hpp): dy_k = x_k dt + r dv, then x_{k+1}."""
    x = M0 + S0 * rng.standard_normal(members)
    dys = np.empty((steps, members))
    sq = np.sqrt(DT)
    for k in range(steps):
        dys[k] = x * DT + R * sq * rng.standard_normal(members)
        x = x - np.sin(x) * DT + Q * sq * rng.standard_normal(members)
    return dys


class NumpyParticleFilter:
    def __init__(self, members, particles, rng):
        self.rng = rng
        self.n = particles
        self.x = M0 + S0 * rng.standard_normal((members, particles))
        self.logw = np.zeros((members, particles))
        self.tmp = np.empty_like(self.x)
        self.w = np.empty_like(self.x)
        self.resamples = 0

    def step(self, dy):
        x, logw, tmp, w = self.x, self.logw, self.tmp, self.w
        # propagate: x += -sin(x) dt + q sqrt(dt) z
        np.sin(x, out=tmp)
        tmp *= -DT
        x += tmp
        self.rng.standard_normal(out=tmp)
        tmp *= Q * np.sqrt(DT)
        x += tmp
        # weight: log g = (x dy - dt x^2 / 2) / r^2 = x (dy - dt x / 2) / r^2
        np.multiply(x, -0.5 * DT, out=tmp)
        tmp += dy[:, None]
        tmp *= x
        tmp *= 1.0 / (R * R)
        logw += tmp
        # log-sum-exp normalization, posterior moments, ESS
        logw -= logw.max(axis=1, keepdims=True)
        np.exp(logw, out=w)
        w /= w.sum(axis=1, keepdims=True)
        mean = np.einsum("mn,mn->m", w, x)
        np.subtract(x, mean[:, None], out=tmp)
        var = np.einsum("mn,mn,mn->m", w, tmp, tmp)
        ess = 1.0 / np.einsum("mn,mn->m", w, w)
        # systematic resampling of the members below N/2
        rows = np.nonzero(ess < 0.5 * self.n)[0]
        if rows.size:
            cs = np.cumsum(w[rows], axis=1)
            cs[:, -1] = 1.0
            points = (self.rng.random((rows.size, 1)) + np.arange(self.n)) / self.n
            for j, row in enumerate(rows):
                x[row] = x[row, np.searchsorted(cs[j], points[j])]
            logw[rows] = 0.0
            self.resamples += rows.size
        return mean, var, ess


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--members", type=int, default=100)
    p.add_argument("--particles", type=int, default=4096)
    p.add_argument("--steps", type=int, default=300, help="timed steps per repetition")
    p.add_argument("--warmup", type=int, default=200)
    p.add_argument("--repetitions", type=int, default=10)
    p.add_argument("--seed", type=int, default=42)
    a = p.parse_args()
    rng = np.random.default_rng(a.seed)
    total = a.warmup + a.steps * a.repetitions
    dys = simulate_observations(a.members, total, rng)
    pf = NumpyParticleFilter(a.members, a.particles, rng)
    for k in range(a.warmup):
        pf.step(dys[k])
    rates = []
    k = a.warmup
    for _ in range(a.repetitions):
        start = time.perf_counter()
        for _ in range(a.steps):
            mean, var, ess = pf.step(dys[k])
            k += 1
        elapsed = time.perf_counter() - start
        if not np.all(np.isfinite(mean)):
            raise SystemExit("pf_numpy.py: non-finite posterior mean")
        rates.append(a.members * a.particles * a.steps / elapsed)
    print(json.dumps({
        "implementation": "numpy", "numpy": np.__version__, "members": a.members, "particles": a.particles,
        "particle_steps_per_s": rates, "median": statistics.median(rates), "min": min(rates), "max": max(rates),
        "resamples_per_member_step": pf.resamples / (a.members * k),
    }))


if __name__ == "__main__":
    main()
