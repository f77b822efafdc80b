"""The ``uvms-pin`` command."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from uvms_pin.arms.command import register as register_compare_arms
from uvms_pin.errors import FunnelViolation, SimulationError, UvmsPinError
from uvms_pin.model import load_uvms
from uvms_pin.rollout import Rollout, write_json_atomic
from uvms_pin.scenario import load_scenario, simulate
from uvms_pin.study.command import register as register_study_commands
from uvms_pin.summary import model_summary
from uvms_pin.validation.command import register as register_validate

EXIT_BAD_INPUT = 2
EXIT_RUN_STOPPED = 3
EXIT_INTERRUPTED = 130  # as a shell reports a process stopped by Ctrl-C


class _ProgressLine:
    """A single updating progress line on stderr, at most a few times per second."""

    def __init__(self, label: str, stream=sys.stderr, min_interval_s: float = 0.5):
        self.label = label
        self.stream = stream
        self.tty = stream.isatty()
        # on a terminal the line is redrawn; in a log file one line every 10 s of wall time
        self.min_interval_s = min_interval_s if self.tty else 10.0
        self.start = time.perf_counter()
        self.last = -1.0

    def __call__(self, t: float, duration: float) -> None:
        now = time.perf_counter()
        if now - self.last < self.min_interval_s and t < duration:
            return
        self.last = now
        elapsed = now - self.start
        frac = t / duration if duration > 0 else 1.0
        eta = elapsed * (1.0 - frac) / frac if frac > 0 else float("nan")
        bar = "#" * int(30 * frac)
        line = f"{self.label} [{bar:<30}] t = {t:7.3f}/{duration:g} s  elapsed {elapsed:6.1f} s  left ~{eta:6.1f} s"
        self.stream.write(f"\r{line}" if self.tty else f"{line}\n")
        self.stream.flush()

    def close(self) -> None:
        if self.tty:
            self.stream.write("\n")
        self.stream.flush()


def write_outputs(rollout: Rollout, out: Path) -> list[Path]:
    """Rollout, metrics.json and figures into ``out``."""
    from uvms_pin.viz.paper_figures import paper_figures
    from uvms_pin.viz.plots import standard_figures

    out.mkdir(parents=True, exist_ok=True)
    rollout.save(out)
    metrics = rollout.metrics()
    write_json_atomic(
        out / "metrics.json",
        {
            "status": rollout.metadata.get("status"),
            "error": rollout.metadata.get("error", ""),
            "seed": rollout.metadata.get("seed"),
            **metrics,
        },
    )
    return paper_figures(rollout, out) + standard_figures(rollout, out)


def _simulate(scenario, args: argparse.Namespace, progress) -> Rollout:
    if not args.live:
        return simulate(scenario, progress=progress)
    from uvms_pin.viz.live import run_live

    return run_live(scenario, port=args.port, speed=args.speed, progress=progress)


def _write_replay(rollout: Rollout, path: Path, **kw) -> Path:
    from uvms_pin.viz.replay import write_replay

    return write_replay(rollout, path, **kw)


def _cmd_run(args: argparse.Namespace) -> int:
    _check_view_options(args)
    scenario = load_scenario(args.scenario)
    out = Path(args.out)
    progress = None if args.quiet else _ProgressLine(scenario.name)
    status = 0
    try:
        rollout = _simulate(scenario, args, progress)
    except (FunnelViolation, SimulationError) as exc:
        rollout = exc.rollout
        status = EXIT_RUN_STOPPED
        message = f"run stopped: {exc}"
    finally:
        if progress is not None:
            progress.close()
    figures = write_outputs(rollout, out)
    if args.html:
        figures.append(_write_replay(rollout, out / "replay.html"))
    metrics = rollout.metrics()
    print(
        f"scenario {scenario.name}: {rollout.metadata['status']}, simulated {metrics['simulated_time_s']:.3f} s in {metrics['wall_time_s']:.2f} s (real-time factor {metrics['real_time_factor']:.2f})"
    )
    print(
        f"wrote {out}/rollout.npz, rollout.json, metrics.json, "
        + ", ".join(p.name for p in figures)
    )
    if status:
        print(message, file=sys.stderr)
    return status


def _check_view_options(args: argparse.Namespace) -> None:
    if not args.speed > 0.0:
        raise UvmsPinError(f"--speed must be positive, got {args.speed}")
    if not 0 <= args.port <= 65535:
        raise UvmsPinError(f"--port must be in 0..65535, got {args.port}")


def _cmd_replay(args: argparse.Namespace) -> int:
    _check_view_options(args)
    if not (args.html or args.live):
        raise UvmsPinError("replay: nothing to do, give --html and/or --live")
    if not args.fps > 0.0:
        raise UvmsPinError(f"--fps must be positive, got {args.fps}")
    rollout = Rollout.load(args.rollout)
    if args.html:
        path = Path(args.out) if args.out else Path(args.rollout) / "replay.html"
        _write_replay(rollout, path, urdf=args.urdf, max_fps=args.fps)
        size_mb = path.stat().st_size / 1e6
        print(f"wrote {path} ({size_mb:.1f} MB, {len(rollout)} samples)")
    if args.live:
        from uvms_pin.viz.live import replay_live
        from uvms_pin.viz.replay import scene_for_rollout

        scene = scene_for_rollout(rollout, urdf=args.urdf)
        replay_live(rollout, scene, port=args.port, speed=args.speed)
    return 0


def _add_view_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--live", action="store_true", help="show the run in meshcat (server on 127.0.0.1)"
    )
    parser.add_argument(
        "--port", type=int, default=7000, help="live view port (default 7000; 0: any free)"
    )
    parser.add_argument(
        "--speed", type=float, default=1.0, help="live playback speed-up over real time"
    )


def _cmd_info(args: argparse.Namespace) -> int:
    uvms = load_uvms(args.urdf, water_density_kg_m3=args.water_density)
    print(model_summary(uvms))
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="uvms-pin", description="Underwater vehicle-manipulator simulation on Pinocchio."
    )
    sub = parser.add_subparsers(dest="command", required=True)
    run = sub.add_parser("run", help="run a scenario file and write rollout, metrics and figures")
    run.add_argument("scenario", help="scenario TOML file")
    run.add_argument("--out", required=True, help="output directory")
    run.add_argument("--quiet", action="store_true", help="no progress line")
    run.add_argument(
        "--html", action="store_true", help="also write replay.html (self-contained, offline)"
    )
    _add_view_options(run)
    run.set_defaults(func=_cmd_run)
    replay = sub.add_parser("replay", help="show a saved rollout: replay.html and/or live")
    replay.add_argument("rollout", help="directory holding rollout.npz and rollout.json")
    replay.add_argument("--html", action="store_true", help="write ROLLOUT/replay.html")
    replay.add_argument("--out", help="write the page here instead of ROLLOUT/replay.html")
    replay.add_argument("--urdf", help="the model's URDF, if it moved since the run")
    replay.add_argument(
        "--fps", type=float, default=30.0, help="replay frames per simulated second (max)"
    )
    _add_view_options(replay)
    replay.set_defaults(func=_cmd_replay)
    info = sub.add_parser("info", help="print a summary of a UVMS URDF")
    info.add_argument("urdf", help="URDF file with the hydrodynamic extension")
    info.add_argument(
        "--water-density", type=float, default=1025.0, help="kg/m^3 (default: sea water)"
    )
    info.set_defaults(func=_cmd_info)
    register_study_commands(sub)
    register_compare_arms(sub)
    register_validate(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except UvmsPinError as exc:
        print(f"uvms-pin: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        print("uvms-pin: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED


if __name__ == "__main__":
    sys.exit(main())
