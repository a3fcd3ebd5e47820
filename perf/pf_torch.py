#!/usr/bin/env python3
"""The particle-filter step of bench_particle_filter.cpp in PyTorch on the GPU, written as a competent user
would: one (M, N) fp64 tensor of particles, the propagate/weight/normalize/moments part as one function
(optionally torch.compile'd, which fuses it into a few kernels), systematic resampling with cumsum +
searchsorted + gather for the members whose ESS fell below N/2 (found with one host sync per step).
Sine model dx = -sin x dt + q dw, dy = x dt + r dv, q = 1, r = 0.5, prior N(1, 1), dt = 1e-3.

usage: pf_torch.py [--members M] [--particles N] [--steps K] [--repetitions R] [--mode eager|compile]
Prints one JSON object: particle_steps_per_s for every repetition, the median and the spread.
"""
import argparse
import json
import math
import statistics
import time

import torch

Q, R, DT, M0, S0 = 1.0, 0.5, 1e-3, 1.0, 1.0


def simulate_observations(members, steps, gen, device):
    x = M0 + S0 * torch.randn(members, dtype=torch.float64, device=device, generator=gen)
    dys = torch.empty(steps, members, dtype=torch.float64, device=device)
    sq = math.sqrt(DT)
    for k in range(steps):
        dys[k] = x * DT + R * sq * torch.randn(members, dtype=torch.float64, device=device, generator=gen)
        x = x - torch.sin(x) * DT + Q * sq * torch.randn(members, dtype=torch.float64, device=device, generator=gen)
    return dys


def propagate_and_weigh(x, logw, dy, noise):
    """One step up to the ESS: returns new particles, normalized log-weights, mean, variance, ESS."""
    x = x - torch.sin(x) * DT + (Q * math.sqrt(DT)) * noise
    logw = logw + x * (dy[:, None] - 0.5 * DT * x) * (1.0 / (R * R))
    logw = logw - torch.logsumexp(logw, dim=1, keepdim=True)
    w = torch.exp(logw)
    mean = (w * x).sum(dim=1)
    var = (w * (x - mean[:, None]) ** 2).sum(dim=1)
    ess = 1.0 / (w * w).sum(dim=1)
    return x, logw, mean, var, ess


def resample(x, logw, ess, n, gen):
    rows = torch.nonzero(ess < 0.5 * n).flatten()  # one host sync per step
    if rows.numel() == 0:
        return 0
    w = torch.exp(logw[rows])
    cs = torch.cumsum(w, dim=1)
    cs[:, -1] = 1.0
    u = torch.rand(rows.numel(), 1, dtype=torch.float64, device=x.device, generator=gen)
    points = (u + torch.arange(n, dtype=torch.float64, device=x.device)) / n
    idx = torch.searchsorted(cs, points).clamp_(max=n - 1)
    x[rows] = torch.gather(x[rows], 1, idx)
    logw[rows] = -math.log(n)
    return rows.numel()


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--members", type=int, default=1000)
    p.add_argument("--particles", type=int, default=65536)
    p.add_argument("--steps", type=int, default=100, help="timed steps per repetition")
    p.add_argument("--warmup", type=int, default=200)
    p.add_argument("--repetitions", type=int, default=10)
    p.add_argument("--mode", choices=["eager", "compile"], default="eager")
    p.add_argument("--seed", type=int, default=42)
    p.add_argument("--device", default="cuda", help="cuda (the benchmark), or cpu to check the script")
    a = p.parse_args()
    device = torch.device(a.device)
    sync = torch.cuda.synchronize if device.type == "cuda" else (lambda: None)
    gen = torch.Generator(device=device)
    gen.manual_seed(a.seed)
    step_fn = torch.compile(propagate_and_weigh) if a.mode == "compile" else propagate_and_weigh
    total = a.warmup + a.steps * a.repetitions
    dys = simulate_observations(a.members, total, gen, device)
    shape = (a.members, a.particles)
    x = M0 + S0 * torch.randn(shape, dtype=torch.float64, device=device, generator=gen)
    logw = torch.full(shape, -math.log(a.particles), dtype=torch.float64, device=device)
    noise = torch.empty(shape, dtype=torch.float64, device=device)
    resamples = 0

    def step(k):
        nonlocal x, logw, resamples
        noise.normal_(generator=gen)
        x, logw, mean, var, ess = step_fn(x, logw, dys[k], noise)
        resamples += resample(x, logw, ess, a.particles, gen)
        return mean

    k = 0
    for _ in range(a.warmup):
        step(k)
        k += 1
    sync()
    rates = []
    for _ in range(a.repetitions):
        start = time.perf_counter()
        for _ in range(a.steps):
            mean = step(k)
            k += 1
        sync()
        elapsed = time.perf_counter() - start
        if not bool(torch.isfinite(mean).all()):
            raise SystemExit("pf_torch.py: non-finite posterior mean")
        rates.append(a.members * a.particles * a.steps / elapsed)
    print(json.dumps({
        "implementation": f"pytorch-{a.mode}", "torch": torch.__version__, "device": torch.cuda.get_device_name() if device.type == "cuda" else "cpu",
        "members": a.members, "particles": a.particles, "particle_steps_per_s": rates,
        "median": statistics.median(rates), "min": min(rates), "max": max(rates),
        "resamples_per_member_step": resamples / (a.members * k),
    }))


if __name__ == "__main__":
    main()
