#!/usr/bin/env python3
"""The particle-filter step of bench_particle_filter.cpp in JAX on the GPU (issue 16 part 3's comparison), as a
competent user would write it: one (M, N) array of particles, the step loop as one `lax.scan` (one compiled
program, no host round trips), normals from jax.random drawn inside the scan, in fp64 or fp32 (every array and
every sum in that type). Propagate, weight, normalize (logsumexp) and the posterior mean, variance and ESS: NO
resampling, which kushner's benchmark includes (amortized): so this is a lower bound on JAX's cost for the same
filter, and ratios against it understate kushner's lead.
Sine model dx = -sin x dt + q dw, dy = x dt + r dv, q = 1, r = 0.5, prior N(1, 1), dt = 1e-3.

usage: pf_jax.py [--members M] [--particles N] [--steps K] [--repetitions R] [--dtype float64|float32]
Prints one JSON object: particle_steps_per_s for every repetition, the median and the spread. Compilation is
excluded (the scan is compiled and run once before the timed repetitions).
"""
import argparse
import json
import math
import statistics
import time

import jax

jax.config.update("jax_enable_x64", True)
import jax.numpy as jnp  # noqa: E402

Q, R, DT, M0, S0 = 1.0, 0.5, 1e-3, 1.0, 1.0


def make_run(members, particles, steps, dtype):
    sq = math.sqrt(DT)

    def step(carry, dy):
        key, x, logw = carry
        key, k = jax.random.split(key)
        noise = jax.random.normal(k, (members, particles), dtype=dtype)
        x = x - jnp.sin(x) * DT + (Q * sq) * noise
        logw = logw + x * (dy[:, None] - 0.5 * DT * x) * (1.0 / (R * R))
        logw = logw - jax.scipy.special.logsumexp(logw, axis=1, keepdims=True)
        w = jnp.exp(logw)
        mean = (w * x).sum(axis=1)
        var = (w * (x - mean[:, None]) ** 2).sum(axis=1)
        ess = 1.0 / (w * w).sum(axis=1)
        return (key, x, logw), (mean[0], var[0], ess[0])

    @jax.jit
    def run(key, x, logw, dys):
        carry, out = jax.lax.scan(step, (key, x, logw), dys)
        return carry[1], carry[2], out

    return run


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--members", type=int, default=1000)
    p.add_argument("--particles", type=int, default=65536)
    p.add_argument("--steps", type=int, default=100, help="steps per timed repetition (one scan)")
    p.add_argument("--repetitions", type=int, default=10)
    p.add_argument("--dtype", choices=["float64", "float32"], default="float64")
    p.add_argument("--seed", type=int, default=42)
    a = p.parse_args()
    dtype = jnp.float64 if a.dtype == "float64" else jnp.float32
    key = jax.random.PRNGKey(a.seed)
    key, kx, ky = jax.random.split(key, 3)
    shape = (a.members, a.particles)
    x = (M0 + S0 * jax.random.normal(kx, shape, dtype=jnp.float64)).astype(dtype)
    logw = jnp.full(shape, -math.log(a.particles), dtype=dtype)
    # Increments of one truth per member are irrelevant to the cost: a fixed plausible dy per step and member.
    dys = (M0 * DT + R * math.sqrt(DT) * jax.random.normal(ky, (a.steps, a.members), dtype=jnp.float64)).astype(dtype)
    run = make_run(a.members, a.particles, a.steps, dtype)
    x, logw, out = run(key, x, logw, dys)  # compile, and the first steps as warm-up
    jax.block_until_ready((x, logw, out))
    rates = []
    for r in range(a.repetitions):
        key = jax.random.fold_in(key, r)
        start = time.perf_counter()
        x, logw, out = run(key, x, logw, dys)
        jax.block_until_ready((x, logw, out))
        elapsed = time.perf_counter() - start
        if not bool(jnp.isfinite(out[0]).all()):
            raise SystemExit("pf_jax.py: non-finite posterior mean")
        rates.append(a.members * a.particles * a.steps / elapsed)
    print(json.dumps({
        "implementation": f"jax-{a.dtype}", "jax": jax.__version__, "device": str(jax.devices()[0]),
        "members": a.members, "particles": a.particles, "particle_steps_per_s": rates,
        "median": statistics.median(rates), "min": min(rates), "max": max(rates),
    }))


if __name__ == "__main__":
    main()
