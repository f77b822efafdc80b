"""A rollout as ONE self-contained HTML file: a meshcat animation that works offline.

The page inlines meshcat's viewer bundle and the scene as base64 msgpack commands decoded
in order (no ``fetch``, no server); a Content-Security-Policy forbids every network
request. The animation is decimated to at most ``max_fps`` frames per simulated second and
``max_frames`` frames in all. Controls: the bar at the bottom (play/pause, time slider) and
meshcat's own panel ("Open Controls" > Animations). ``replay.html#t=4.5`` opens paused at
t = 4.5 s.
"""

from __future__ import annotations

import base64
import html
import json
import math
from pathlib import Path
from typing import Any

import meshcat
import meshcat.animation
import meshcat.geometry as mg
import numpy as np
import pinocchio as pin

from uvms_pin.apps.viz.camera_panel import PANELS_SCRIPT, image_panels
from uvms_pin.apps.viz.meshcat_scene import (
    ROOT,
    EnvironmentView,
    Frame,
    SceneStyle,
    UvmsScene,
    recording_visualizer,
    tip_position,
)
from uvms_pin.apps.viz.surface import surface_view_of
from uvms_pin.apps.viz.world_view import WorldView
from uvms_pin.errors import VizError
from uvms_pin.flow import flow_from_record
from uvms_pin.model.urdf.load import load_uvms
from uvms_pin.model.uvms import DEFAULT_WATER_DENSITY_KG_M3
from uvms_pin.results.atomic import write_text_atomic
from uvms_pin.results.rollout import Rollout

REPLAY_FILE = "replay.html"
_TRAIL_CHUNKS = 60
_REFERENCE_COLOR = 0xFF40FF
_TRAIL_POINTS = 4000


def _viewer_bundle() -> str:
    path = Path(meshcat.__file__).parent / "viewer" / "dist" / "main.min.js"
    return path.read_text(encoding="utf-8")


def scene_for_rollout(
    rollout: Rollout,
    *,
    urdf: str | Path | None = None,
    style: SceneStyle | None = None,
    show: str = "visual",
    also_world_m: np.ndarray | None = None,
) -> UvmsScene:
    """The scene of a rollout: its model (``metadata['model_source']`` or ``urdf``), the
    world it recorded (``metadata['world']``: contact, current, waves), its extent (with
    the points ``also_world_m`` (n, 3): other robots to keep in view); ``show`` the robot's
    visual geometry, its collision shapes or both (`UvmsScene`)."""
    if len(rollout) == 0:
        raise VizError("the rollout has no sample to show")
    meta = rollout.metadata
    world = meta.get("world") or {}
    source = Path(urdf) if urdf is not None else meta.get("model_source")
    if not source or not Path(source).is_file():
        raise VizError(
            f"model file {source!r} of the rollout not found; pass the URDF explicitly "
            "(uvms-pin replay DIR --urdf FILE)"
        )
    density = float(world.get("water_density_kg_m3", DEFAULT_WATER_DENSITY_KG_M3))
    uvms = load_uvms(source, water_density_kg_m3=density)
    data = uvms.model.createData()
    tips = np.array([tip_position(uvms, data, q) for q in _every(rollout.q, 400)])
    extent = np.vstack([tips, rollout.q[:, :3], *([] if also_world_m is None else [also_world_m])])
    surface = surface_view_of(
        flow_from_record(world.get("flow")),
        bool(world.get("free_surface")),
        extent.mean(axis=0)[:2],
    )
    if surface is not None:  # keep the mean surface above the vehicle in view
        extent = np.vstack([extent, [*rollout.q[0, :2], 0.0]])
    return UvmsScene(
        uvms,
        environment=EnvironmentView.from_record(world.get("contact"), tips[0]),
        current_world_m_s=world.get("current_world_m_s", [0.0, 0.0, 0.0]),
        show_desired="force_desired_world_N" in rollout.signals,
        extent_world_m=extent,
        style=style,
        surface=surface,
        world=WorldView.from_record(world.get("world"), extent.mean(axis=0)),
        show=show,
    )


def _every(rows: np.ndarray, at_most: int) -> np.ndarray:
    """At most ``at_most`` rows, evenly spread, first and last included."""
    idx = np.unique(np.linspace(0, len(rows) - 1, min(len(rows), at_most)).round().astype(int))
    return rows[idx]


def frame_times(time_s: np.ndarray, max_fps: float, max_frames: int) -> tuple[np.ndarray, float]:
    """Sample indices of the animation frames and the frame rate [frames per simulated s]."""
    t0, t1 = float(time_s[0]), float(time_s[-1])
    duration = t1 - t0
    if duration <= 0.0:
        return np.array([0]), max_fps
    fps = min(max_fps, (max_frames - 1) / duration)
    n = math.floor(duration * fps + 1e-9) + 1
    wanted = t0 + np.arange(n) / fps
    idx = np.clip(np.searchsorted(time_s, wanted), 0, len(time_s) - 1)
    before = np.clip(idx - 1, 0, len(time_s) - 1)
    closer = np.abs(time_s[before] - wanted) < np.abs(time_s[idx] - wanted)
    idx = np.where(closer, before, idx)
    if idx[-1] != len(time_s) - 1:
        idx = np.append(idx, len(time_s) - 1)
    return idx, fps


def replay_html(
    rollout: Rollout,
    *,
    urdf: str | Path | None = None,
    max_fps: float = 30.0,
    max_frames: int = 1800,
    style: SceneStyle | None = None,
    show: str = "visual",
    others: Any = None,
) -> str:
    """The replay page of a rollout (a string of HTML); ``show``: the robot's ``"visual"``
    geometry, its ``"collision"`` shapes or ``"both"``; ``others``: more robots drawn beside
    it (`uvms_pin.apps.viz.robots_replay.OtherRobots`: their extent, their geometry and
    their poses at each of the rollout's samples)."""
    good = np.isfinite(rollout.time_s) & np.all(np.isfinite(rollout.q), axis=1)
    if not np.any(good):
        raise VizError("the rollout has no finite sample to show")
    also = None if others is None else others.extent_world_m
    scene = scene_for_rollout(rollout, urdf=urdf, style=style, show=show, also_world_m=also)
    vis, window = recording_visualizer()
    scene.build(vis)
    if others is not None:
        others.build(vis[ROOT])
    rows = np.flatnonzero(good)  # the rollout's sample of each good row

    time_s = rollout.time_s[good]
    q = rollout.q[good]
    measured = rollout.wrench_measured_world[good, :3]
    desired = rollout.signals.get("force_desired_world_N")
    desired = desired[good, :3] if desired is not None else None
    contacts, free, object_contact = (
        None if rollout.signals.get(name) is None else rollout.signals[name][good]
        for name in ("world_contact", "free_objects", "free_object_contact")
    )
    fixtures = _fixture_rows(rollout, scene, good)
    idx, fps = frame_times(time_s, max_fps, max_frames)
    t0 = float(time_s[0])
    keys = (time_s[idx] - t0) * fps  # animation time in frames (meshcat's convention)

    anim = meshcat.animation.Animation(default_framerate=fps)
    root = vis[ROOT]
    for key, i in zip(keys, idx, strict=True):
        frame = Frame(
            float(time_s[i]),
            q[i],
            measured[i],
            None if desired is None else desired[i],
            None if contacts is None else contacts[i],
            None if free is None else free[i],
            None if object_contact is None else object_contact[i],
            {name: rows_[i] for name, rows_ in fixtures.items()},
        )
        at = anim.at_frame(root, float(key))
        poses = scene.poses(frame)
        if others is not None:
            poses.update(others.poses(int(rows[i])))
        for path, (position, quat, scale) in poses.items():
            node = at[path]
            node.set_property("position", "vector3", position.tolist())
            node.set_property("quaternion", "quaternion", quat.tolist())
            node.set_property("scale", "vector3", scale.tolist())
    _add_trail(scene, root, anim, time_s, q, t0, fps, float(keys[-1]))
    reference = reference_path_world(rollout)
    legend = scene.legend()
    if reference is not None:
        root["reference"].set_object(_reference_object(reference[good]))
        legend += "; the task's reference path (magenta)"
    vis.set_animation(anim, play=True, repetitions=math.inf)

    meta = rollout.metadata
    info = {
        "title": f"uvms-pin replay: {meta.get('scenario', 'rollout')}",
        "description": meta.get("description", ""),
        "status": meta.get("status", ""),
        "stopped": rollout.status.summary() or "",
        "t0": t0,
        "duration": float(time_s[-1] - t0),
        "fps": fps,
        "frames": len(idx),
        "legend": legend,
    }
    return _page(window.commands, info, image_panels(rollout, t0))


def _fixture_rows(rollout: Rollout, scene: UvmsScene, good: np.ndarray) -> dict[str, np.ndarray]:
    """Each drawn fixture's logged joint positions (its signal, named after it), good rows."""
    names = () if scene.world is None else (f.name for f in scene.world.fixtures)
    return {n: rollout.signals[n][good] for n in names if rollout.signals.get(n) is not None}


def reference_path_world(rollout: Rollout) -> np.ndarray | None:
    """A tracking task's reference positions (n, 3) in the world frame [m] (a reference
    given in the vehicle frame moved with the vehicle's logged pose); None without a task."""
    reference = rollout.signals.get("task_reference_position")
    task = rollout.metadata.get("task") or {}
    if reference is None:
        return None
    if task.get("frame") != "vehicle":
        return np.array(reference, dtype=float)
    out = np.empty_like(reference)
    for k, (row, point) in enumerate(zip(rollout.q, reference, strict=True)):
        rotation = pin.Quaternion(row[6], row[3], row[4], row[5]).normalized().toRotationMatrix()
        out[k] = row[:3] + rotation @ point
    return out


def _reference_object(points_world_m: np.ndarray) -> mg.Line:
    pts = np.asarray(points_world_m, dtype=np.float32).reshape(-1, 3)
    return mg.Line(mg.PointsGeometry(pts.T), mg.LineBasicMaterial(color=_REFERENCE_COLOR))


def scene_html(scene: UvmsScene, frame: Frame, *, title: str, description: str = "") -> str:
    """A page showing ``scene`` at one instant (no animation), e.g. a model at rest."""
    vis, window = recording_visualizer()
    scene.build(vis)
    scene.show(vis, frame)
    info = {
        "title": title,
        "description": description,
        "status": "",
        "t0": float(frame.time_s),
        "duration": 0.0,
        "fps": 1.0,
        "frames": 1,
        "legend": scene.legend(),
    }
    return _page(window.commands, info)


def _add_trail(scene, root, anim, time_s, q, t0, fps, last_key) -> None:
    """The tip's trail in chunks that appear as the animation passes them."""
    rows = np.unique(np.linspace(0, len(q) - 1, min(len(q), _TRAIL_POINTS)).astype(int))
    tips = np.array([scene.ee_position(q[i]) for i in rows])
    keys = (time_s[rows] - t0) * fps
    n_chunks = max(1, min(_TRAIL_CHUNKS, len(rows) - 1))
    bounds = np.linspace(0, len(rows) - 1, n_chunks + 1).round().astype(int)
    for j in range(n_chunks):
        a, b = bounds[j], max(bounds[j + 1], bounds[j] + 1)
        node = root[f"trail/{j:03d}"]
        node.set_object(scene.trail_object(tips[a : b + 1]))
        appear = float(keys[min(b, len(keys) - 1)])
        track = anim.at_frame(root, 0.0)[f"trail/{j:03d}"]
        track.set_property("visible", "boolean", appear <= 0.0)
        if appear > 0.0:
            anim.at_frame(root, min(appear, last_key))[f"trail/{j:03d}"].set_property(
                "visible", "boolean", True
            )


def write_replay(rollout: Rollout, path: str | Path, **kw: Any) -> Path:
    """Write the replay page of ``rollout`` to ``path`` (atomically); returns the path."""
    return write_page(replay_html(rollout, **kw), path)


def write_page(text: str, path: str | Path) -> Path:
    """Write an HTML page atomically (never a half-written file); returns the path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    return write_text_atomic(path, text)


_CSP = (
    "default-src 'none'; script-src 'unsafe-inline' 'unsafe-eval'; style-src 'unsafe-inline'; "
    "img-src data: blob:; font-src data:; connect-src data: blob:; worker-src blob:"
)

_STYLE = """
body { margin: 0; background: #04162e; font: 13px/1.35 sans-serif; }
#meshcat-pane { width: 100vw; height: 100vh; overflow: hidden; }
#uvms-info { position: absolute; left: 8px; top: 8px; max-width: 46vw; color: #e8f2ff;
  background: rgba(0, 20, 40, 0.55); padding: 6px 9px; border-radius: 4px; }
#uvms-info b { font-size: 14px; }
#uvms-info .uvms-stopped { color: #ff8a80; }
#uvms-bar { position: absolute; left: 0; right: 0; bottom: 0; display: flex; gap: 10px;
  align-items: center; padding: 6px 12px; background: rgba(0, 20, 40, 0.6); color: #e8f2ff; }
#uvms-bar button { width: 72px; }
#uvms-slider { flex: 1; }
#uvms-time { font-family: monospace; min-width: 150px; text-align: right; }
#uvms-panels { position: absolute; right: 8px; top: 30px; max-width: 32vw; display: flex;
  flex-direction: column; gap: 6px; }
#uvms-panels img { max-width: 32vw; max-height: 42vh; border: 1px solid #e8f2ff; }
"""

_SCRIPT = """
const viewer = new MeshCat.Viewer(document.getElementById("meshcat-pane"));
function decodeCommand(b64) {
  const bin = atob(b64);
  const bytes = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
  return bytes;
}
for (const command of UVMS_COMMANDS) viewer.handle_command_bytearray(decodeCommand(command));
if (UVMS_INFO.duration <= 0) document.getElementById("uvms-bar").style.display = "none";
const animator = viewer.animator;
const slider = document.getElementById("uvms-slider");
const button = document.getElementById("uvms-play");
const label = document.getElementById("uvms-time");
slider.max = UVMS_INFO.duration;
slider.step = 1 / UVMS_INFO.fps;
function currentTime() {
  return animator.actions.reduce((acc, action) => Math.max(acc, action.time), 0);
}
function refresh() {
  const t = currentTime();
  if (document.activeElement !== slider) slider.value = t;
  showPanels(t);
  label.textContent = "t = " + (UVMS_INFO.t0 + t).toFixed(2) + " / "
    + (UVMS_INFO.t0 + UVMS_INFO.duration).toFixed(2) + " s";
  button.textContent = animator.playing ? "pause" : "play";
}
function seek(t) {
  animator.seek(t);
  animator.display_progress(t);
  refresh();
}
button.addEventListener("click", () => {
  if (animator.playing) animator.pause(); else animator.play();
  refresh();
});
slider.addEventListener("input", () => seek(parseFloat(slider.value)));
function seekFromHash() {
  const m = /t=([0-9.eE+-]+)/.exec(location.hash);
  if (m) { animator.pause(); seek(parseFloat(m[1]) - UVMS_INFO.t0); }
}
window.addEventListener("hashchange", seekFromHash);
seekFromHash();
(function loop() { refresh(); requestAnimationFrame(loop); })();
"""


def _page(commands: list[bytes], info: dict[str, Any], panels: list[dict] = ()) -> str:
    encoded = ",\n".join(f'"{base64.b64encode(c).decode("ascii")}"' for c in commands)
    bundle = _viewer_bundle().replace("</script", "<\\/script")
    esc = html.escape
    info_json = json.dumps(info).replace("</", "<\\/")
    panels_json = json.dumps(list(panels)).replace("</", "<\\/")
    images = "".join(f'<img id="{p["id"]}" alt="{esc(p["label"])}">' for p in panels)
    image = f'<div id="uvms-panels">{images}</div>' if panels else ""
    description = f"<br>{esc(info['description'])}" if info["description"] else ""
    frames = ""
    if info["duration"] > 0:
        frames = f"<br>{info['frames']} frames at {info['fps']:.3g} per simulated second"
    status = f" ({esc(info['status'])})" if info["status"] else ""
    if info.get("stopped"):
        status += f'<br><span class="uvms-stopped">{esc(info["stopped"])}</span>'
    return f"""<!DOCTYPE html>
<html>
<head>
<meta charset="utf-8">
<meta http-equiv="Content-Security-Policy" content="{_CSP}">
<title>{esc(info["title"])}</title>
<style>{_STYLE}</style>
</head>
<body>
<div id="meshcat-pane"></div>
<div id="uvms-info"><b>{esc(info["title"])}</b>{status}{description}<br>
{esc(info["legend"])}{frames}</div>
<div id="uvms-bar"><button id="uvms-play">pause</button>
<input id="uvms-slider" type="range" min="0" value="0"><span id="uvms-time"></span></div>
{image}
<script>
{bundle}
</script>
<script>
const UVMS_INFO = {info_json};
const UVMS_PANELS = {panels_json};
{PANELS_SCRIPT}
const UVMS_COMMANDS = [
{encoded}
];
{_SCRIPT}
</script>
</body>
</html>
"""
