"""The free surface: the analytic cases (submerged volumes, a floating box's draft and heave
period, a sphere's cap-volume root, the small-angle restoring moments rho g V GM, energy, the
heave in long waves) as errors against their closed forms, and the surfacing scenario."""

from __future__ import annotations

import itertools
import json
import math
import tempfile
from pathlib import Path

import numpy as np
import pinocchio as pin
from _common import producer_cli, publish_figure, scratch, uvms_pin, write_result
from scipy.integrate import quad

import uvms_pin as up
from uvms_pin.flow import AiryWave
from uvms_pin.hydro.submerged import Polyhedron, Sphere
from uvms_pin.hydro.submerged_cylinder import Cylinder
from uvms_pin.physics.floating import floating_equilibrium
from uvms_pin.sim.integrators import RK4
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.system import System

RHO, G = 1025.0, 9.81
A, B, C = 1.0, 0.6, 0.4
MASS = 0.4 * RHO * A * B * C
A33 = 150.0


def _normals(rng: np.random.Generator, count: int) -> list[np.ndarray]:
    return [n / np.linalg.norm(n) for n in rng.normal(size=(count, 3))]


def volume_errors() -> dict[str, float]:
    """Worst |V - V_exact| / V_full over 50 tilts x 13 heights per shape."""
    rng = np.random.default_rng(1)
    sphere, box, cylinder = Sphere(0.37), Polyhedron.box((0.8, 0.5, 0.3)), Cylinder(0.21, 1.3)
    worst = {"sphere (cap)": 0.0, "box (corner formula)": 0.0, "cylinder (segment integral)": 0.0}
    for n in _normals(rng, 50):
        for d in np.linspace(-0.45, 0.45, 13):
            top = min(max(d, -0.37), 0.37)
            exact = math.pi * (0.37**2 * (top + 0.37) - (top**3 + 0.37**3) / 3)
            worst["sphere (cap)"] = max(
                worst["sphere (cap)"], abs(sphere.below(n, d).volume_m3 - exact) / sphere.volume_m3
            )
            m, half, size = np.abs(n), np.array([0.4, 0.25, 0.15]), np.array([0.8, 0.5, 0.3])
            total = sum(
                (-1) ** sum(c) * max(d - m @ (-half + np.array(c) * size), 0.0) ** 3
                for c in itertools.product((0, 1), repeat=3)
            ) / (6 * np.prod(m))
            worst["box (corner formula)"] = max(
                worst["box (corner formula)"],
                abs(box.below(n, d).volume_m3 - total) / box.volume_m3,
            )
            worst["cylinder (segment integral)"] = max(
                worst["cylinder (segment integral)"],
                abs(cylinder.below(n, d).volume_m3 - _cylinder(0.21, 1.3, n, d))
                / cylinder.volume_m3,
            )
    return worst


def _cylinder(r: float, length: float, n: np.ndarray, d: float) -> float:
    n_p, nz = math.hypot(n[0], n[1]), n[2]

    def segment(s: float) -> float:
        t = min(max((d - nz * s) / n_p, -r), r)
        return r * r * (math.pi - math.acos(t / r)) + t * math.sqrt(r * r - t * t)

    cuts = [s for s in ((d - n_p * r) / nz, (d + n_p * r) / nz) if abs(s) < length / 2]
    points = sorted([-length / 2, length / 2, *cuts])
    return sum(
        quad(segment, a, b, epsabs=1e-16, epsrel=1e-12)[0] for a, b in itertools.pairwise(points)
    )


def _load(text: str) -> up.UVMS:
    with tempfile.NamedTemporaryFile("w", suffix=".urdf", delete=False) as f:
        f.write(text)
    return up.load_uvms(f.name)


def _body(mass, inertia, volume, collision, added=(0,) * 6, damping=(0,) * 6) -> up.UVMS:
    def s(x):
        return " ".join(str(v) for v in x)

    return _load(
        f'<robot name="one"><link name="body"><inertial><mass value="{mass}"/>'
        f'<inertia ixx="{inertia[0]}" iyy="{inertia[1]}" izz="{inertia[2]}" ixy="0" ixz="0" iyz="0"/>'
        f"</inertial><collision><geometry>{collision}</geometry></collision><hydrodynamics>"
        f'<volume value="{volume}"/><added_mass diagonal="{s(added)}"/>'
        f'<linear_damping diagonal="{s(damping)}"/></hydrodynamics></link></robot>'
    )


def _box(damping=(0,) * 6) -> up.UVMS:
    inertia = (
        MASS * (B * B + C * C) / 12,
        MASS * (A * A + C * C) / 12,
        MASS * (A * A + B * B) / 12,
    )
    return _body(
        MASS, inertia, A * B * C, f'<box size="{A} {B} {C}"/>', (60, 90, A33, 4, 5, 6), damping
    )


def _at(uvms, z=0.0, rpy=(0.0, 0.0, 0.0)) -> np.ndarray:
    q = uvms.neutral_configuration()
    q[2] = z
    q[3:7] = pin.Quaternion(pin.rpy.rpyToMatrix(*rpy)).coeffs()
    return q


def _run(uvms, q, v, duration_s, step_s, every=1, flow=None):
    system = System(Plant(uvms, flow=flow, free_surface=True))
    system.start(system.initial_state(q, v))
    period, out = step_s * every, [(0.0, q, v)]
    for k in range(round(duration_s / period)):
        q, v = system.advance(RK4(step_s), k * period, q, v, np.zeros(uvms.nv), (k + 1) * period)
        out.append(((k + 1) * period, q, v))
    return out


def floating_cases() -> list[tuple[str, str, float, float]]:
    """(case, formula, simulated or solved, analytic)."""
    rows = []
    draft = MASS / (RHO * A * B)
    damped = _box((50, 50, 400, 40, 40, 40))
    rows.append(
        (
            "box draft, statics [m]",
            "m / (rho a b)",
            C / 2 - floating_equilibrium(damped, _at(damped, 0.1, (0.05, -0.03, 0.2)))[2],
            draft,
        )
    )
    settled = _run(damped, _at(damped, 0.3, (0.1, 0.05, 0.0)), np.zeros(6), 30.0, 2e-3, 10)[-1][1]
    rows.append(
        (
            "box draft, dropped and settled (RK4 2 ms) [m]",
            "m / (rho a b)",
            C / 2 - settled[2],
            draft,
        )
    )
    r, m = 0.25, 0.3 * RHO * 4 / 3 * math.pi * 0.25**3
    ball = _body(m, (0.4 * m * r * r,) * 3, 4 / 3 * math.pi * r**3, f'<sphere radius="{r}"/>')
    roots = np.roots([-math.pi / 3, math.pi * r, 0.0, -m / RHO])
    h = next(x.real for x in roots if abs(x.imag) < 1e-12 and 0 < x.real < 2 * r)
    rows.append(
        (
            "sphere immersion, statics [m]",
            "root of pi h^2 (3r - h) / 3 = m / rho",
            r - floating_equilibrium(ball, _at(ball, 0.2), free_attitude=False)[2],
            h,
        )
    )
    box = _box()
    q_eq = floating_equilibrium(box, _at(box), free_attitude=False)
    expected = 2 * math.pi * math.sqrt((MASS + (C / 2 - q_eq[2]) / C * A33) / (RHO * G * A * B))
    rows.append(
        (
            "box heave period [s]",
            "2 pi sqrt((m + f A33) / (rho g a b))",
            _period(box, q_eq),
            expected,
        )
    )
    volume = MASS / RHO
    for axis, name, second in ((0, "roll", A * B**3 / 12), (1, "pitch", B * A**3 / 12)):
        rpy = [0.0, 0.0, 0.0]
        rpy[axis] = 1e-4
        moment = up.bias_forces(box, _at(box, C / 2 - draft, rpy), np.zeros(6), free_surface=True)[
            3 + axis
        ]
        gm = draft / 2 + second / volume - C / 2
        rows.append(
            (
                f"box {name} moment at 1e-4 rad [N m]",
                "rho g V GM phi, GM = KB + BM - KG",
                moment,
                RHO * G * volume * gm * 1e-4,
            )
        )
    return rows


def _period(uvms, q_eq) -> float:
    q0 = q_eq.copy()
    q0[2] += 1e-3
    samples = _run(uvms, q0, np.zeros(6), 5.0, 5e-4)
    t = np.array([s[0] for s in samples])
    z = np.array([s[1][2] for s in samples]) - q_eq[2]
    k = np.flatnonzero((z[:-1] < 0) & (z[1:] >= 0))
    times = t[k] - z[k] * (t[k + 1] - t[k]) / (z[k + 1] - z[k])
    return float(np.mean(np.diff(times)))


def energy_and_waves() -> dict[str, float]:
    box = _box()
    q0, v0 = _at(box, 0.12, (0.25, -0.15, 0.3)), np.array([0.2, -0.1, -0.6, 0.4, 0.3, -0.2])

    def energy(q, v):
        return up.kinetic_energy(box, q, v, free_surface=True) + up.potential_energy(
            box, q, free_surface=True
        )

    kinetic, e0 = up.kinetic_energy(box, q0, v0, free_surface=True), energy(q0, v0)
    samples = _run(box, q0, v0, 3.0, 1e-3, 20)
    drift = max(abs(energy(q, v) - e0) for _, q, v in samples) / kinetic
    damped = _box((20, 20, 60, 3, 3, 3))
    series = [
        up.kinetic_energy(damped, q, v, free_surface=True)
        + up.potential_energy(damped, q, free_surface=True)
        for _, q, v in _run(damped, q0, v0, 3.0, 1e-3, 10)
    ]
    riding = _box((40, 40, 200, 5, 5, 5))
    q_eq = floating_equilibrium(riding, _at(riding), free_attitude=False)
    wave = AiryWave(0.05, 30.0)
    samples = _run(riding, q_eq, np.zeros(6), 120.0, 4e-3, 5, wave)
    t = np.array([s[0] for s in samples])
    z = np.array([s[1][2] for s in samples]) - q_eq[2]
    late, w = t >= 60.0, 2 * math.pi / 30.0
    basis = np.column_stack([np.cos(w * t[late]), np.sin(w * t[late]), np.ones(late.sum())])
    c = np.linalg.lstsq(basis, z[late], rcond=None)[0]
    return {
        "energy drift without damping / initial kinetic energy (3 s, RK4 1 ms)": drift,
        "largest energy increase with damping / initial kinetic energy": max(np.diff(series))
        / kinetic,
        "heave RAO in a 30 s swell (-> 1)": math.hypot(c[0], c[1]) / 0.05,
    }


def surfacing(out: Path) -> tuple[dict, float]:
    uvms_pin("run", "scenarios/surfacing.toml", "--out", str(out), "--quiet")
    metrics = json.loads((out / "metrics.json").read_text())
    rollout = up.Rollout.load(out)
    vehicle = up.load_uvms("models/lbv150.urdf")
    resting = floating_equilibrium(vehicle, rollout.q[-1])
    return metrics, float(rollout.q[-1, 2] - resting[2])


def main() -> None:
    lines = ["| shape | worst volume error / full volume |", "|---|---|"]
    lines += [f"| {k} | {v:.1e} |" for k, v in volume_errors().items()]
    lines += [
        "",
        "| case | analytic | uvms-pin | analytic value | relative error |",
        "|---|---|---|---|---|",
    ]
    for case, formula, got, exact in floating_cases():
        lines.append(
            f"| {case} | {formula} | {got:.9g} | {exact:.9g} | {abs(got - exact) / abs(exact):.1e} |"
        )
    lines += ["", "| energy and waves | value |", "|---|---|"]
    lines += [f"| {k} | {v:.8g} |" for k, v in energy_and_waves().items()]
    out = scratch("surface")
    metrics, offset = surfacing(out)
    lines += [
        "",
        "`uvms-pin run scenarios/surfacing.toml` (the LBV150 alone, no thrust, from 2 m):",
        "",
        "| metric | value |",
        "|---|---|",
        f"| status | {metrics['status']} |",
        f"| time partly out of the water [s] | {metrics['time_partly_out_of_water_s']:.2f} |",
        f"| smallest wet fraction | {metrics['wet_fraction_min']:.4f} |",
        f"| final z minus the floating equilibrium's [m] | {offset:.1e} |",
        f"| largest energy increase between samples [J] | {metrics['energy_max_increase_J']:.1e} |",
        "",
        "![surfacing](../surfacing.png)",
    ]
    publish_figure(out / "surface.png", "surfacing.png")
    write_result(
        "surface", "The free surface", "python scripts/results/surface.py", "\n".join(lines)
    )


if __name__ == "__main__":
    producer_cli(__doc__)
    main()
