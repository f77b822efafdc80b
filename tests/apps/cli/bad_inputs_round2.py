"""The bad-input corpus, second round (issue 22): what a new user broke in an afternoon, and
the rest of each class. One block per issue item; the runner is ``test_bad_inputs.py``."""

from __future__ import annotations

import re
import struct

from cli_support import ROOT, URDF
from corpus import (
    Case,
    realistic_with,
    rollout_kept,
    scenario_with,
    steps,
    urdf_with,
    write,
)

ARM_JOINTS = ("arm_joint1", "arm_joint2", "arm_joint3", "arm_joint4")


def _joint_type(kind: str, *names: str) -> str:
    """The reference URDF with joints ``names`` of type ``kind``."""
    return urdf_with(
        **{
            f'<joint name="{n}" type="revolute">': f'<joint name="{n}" type="{kind}">'
            for n in names
        }
    )


def _controller(body: str, init: str = "self.nv = uvms.nv") -> str:
    """A user's controller module ``ctrl.py`` with class ``C``."""
    return (
        "import numpy as np\n"
        "from uvms_pin.control.base import Controller\n\n"
        "class C(Controller):\n"
        "    def __init__(self, uvms, **params):\n"
        f"        {init}\n\n"
        "    def compute(self, t, m):\n"
        + "".join(f"        {line}\n" for line in body.splitlines())
    )


def _with_controller(module: str, params: str = "") -> object:
    """Setup: ``ctrl.py`` and a passive scenario ``s.toml`` run by its controller ``C``
    (continuous: the arm on its compliant stops, whose stiffest, arm_joint4's, RK4 holds up
    to a 1.24 ms step; the passive scenario's 2 ms is refused before the run)."""
    extra = f'\n[controller]\ntype = "ctrl:C"\n{params}'
    text = scenario_with(_URDF, 0.2, extra, **{"step_s = 0.002": "step_s = 0.001"})
    return steps(write("ctrl.py", module), write("s.toml", text))


_URDF = str(URDF)

#: ``python api.py SCENARIO OUT``: a run whose controller is replaced in code, saved
_SET_IN_CODE = """import sys
import numpy as np
from uvms_pin.apps.outputs import write_results
from uvms_pin.control.base import Controller
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.run import simulate
class Hold(Controller):
    def __init__(self, nv):
        self.nv, self.gain = nv, 3.0
    def compute(self, t, m):
        return np.zeros(self.nv)
scenario = load_scenario(sys.argv[1], {"controller.type": "none"})
scenario.controller_factory = lambda uvms: Hold(uvms.nv)
write_results(simulate(scenario, progress=False), __import__("pathlib").Path(sys.argv[2]))
"""


def _recorded_as_set_in_code(case_dir) -> None:
    import json

    metadata = json.loads((case_dir / "new" / "rollout.json").read_text())
    assert metadata["controller"] == {
        "class": "__main__:Hold",
        "type": "__main__:Hold",
        "params": {"nv": 10, "gain": 3.0},
    }
    assert metadata["parameters"]["controller"]["set_in_code"] is True


#: a policy writing into its observations: the episode is the one of a policy that did not
_GYM_MEDDLER = """import gymnasium as gym, numpy as np, uvms_pin.apps.gym
def episode(meddle):
    env = gym.make("uvms_pin/ForceTracking-v0", overrides={"scenario.duration_s": 0.02}).unwrapped
    obs, _ = env.reset(seed=1)
    seen = [obs.copy()]
    for _ in range(5):
        if meddle:
            obs[:] = 99.0
        obs, *_ = env.step(np.zeros(env.action_space.shape))
        seen.append(obs.copy())
    return np.array(seen)
assert np.array_equal(episode(True), episode(False))
"""

#: ``python diskfull.py NAME uvms-pin-args``: uvms-pin on a disk that refuses file NAME
DISK_FULL = """import errno, os, sys
from uvms_pin.apps.cli.main import main
full = sys.argv.pop(1)
real = os.replace
def replace(src, dst, *args, **kw):
    if os.path.basename(dst) == full:
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(src))
    return real(src, dst, *args, **kw)
os.replace = replace
sys.exit(main())
"""
_RUN_NEW = ("run", "s.toml", "--out", "new", "--quiet")


def _first_row_is(table: str, start: str):
    """After: the first data row of the CSV file ``table`` starts with ``start``."""

    def check(case_dir) -> None:
        row = (case_dir / table).read_text().splitlines()[1]
        assert row.startswith(start), row

    return check


_DATA = str(ROOT / "data" / "hinsdale2023")
_SEA = (
    (ROOT / "scenarios" / "sea_state_force_tracking.toml")
    .read_text()
    .replace('"../models/uvms_lbv150.urdf"', f'"{URDF}"')
)

_SURFACING = str(ROOT / "scenarios" / "surfacing.toml")
#: a binary STL of one triangle: a surface enclosing no volume
_FLAT_STL = (
    b"\0" * 80
    + struct.pack("<I", 1)
    + struct.pack("<12f", 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0)
    + b"\0\0"
)
_BASE_BOX = '<geometry><box size="0.53 0.245 0.254"/></geometry>'
_FLAT_MESH = '<geometry><mesh filename="flat.stl"/></geometry>'


def _arm_link1_derived_from(collision: str) -> str:
    """The reference URDF with arm_link1's <hydrodynamics> removed (derived from its
    collision shape) and that shape replaced by ``collision``."""
    text = URDF.read_text()
    start = text.index('<link name="arm_link1">')
    end = text.index("</link>", start)
    link = re.sub(r"<hydrodynamics>.*?</hydrodynamics>", "", text[start:end], flags=re.S)
    link = re.sub(
        r"<collision>.*?</collision>", f"<collision>{collision}</collision>", link, flags=re.S
    )
    return text[:start] + link + text[end:]


ROUND_TWO = [
    # ---- 1. a controller cannot change the simulation through its measurement ----------
    Case("run-controller-freezes-the-vehicle", _RUN_NEW, ("run stopped", "compute() raised at t = 0 s", "ValueError: assignment destination is read-only"), _with_controller(_controller("m.v[:] = 0\nreturn np.zeros(self.nv)")), code=3, traceback_of="ctrl.py", after=rollout_kept("new", "error")),
    Case("run-controller-teleports-the-vehicle", _RUN_NEW, ("compute() raised", "read-only"), _with_controller(_controller("m.q[0] = 99.0\nreturn np.zeros(self.nv)")), code=3, traceback_of="ctrl.py", after=rollout_kept("new", "error")),
    Case("run-controller-writes-the-wrench", _RUN_NEW, ("compute() raised", "read-only"), _with_controller(_controller("m.force_world_N[:] = 1.0\nreturn np.zeros(self.nv)")), code=3, traceback_of="ctrl.py", after=rollout_kept("new", "error")),
    # ---- 2. continuous joints: one position per joint, no limits -----------------------
    Case("run-continuous-joints-given-cos-and-sin", ("run", "s.toml", "--out", "new", "--set", "initial.joint_positions_rad=[1,0,1,0,1,0,1,0]"), ("initial.joint_positions_rad", "needs 4 numbers, got 8"), steps(write("c.urdf", _joint_type("continuous", *ARM_JOINTS)), write("s.toml", scenario_with("c.urdf"))), watch="new"),
    Case("run-continuous-beside-a-limited-joint-outside", ("run", "s.toml", "--out", "new", "--set", "initial.joint_positions_rad=[3.0, 2.5, 0, 0]"), ("outside the joint limits for arm_joint2",), steps(write("c.urdf", _joint_type("continuous", "arm_joint1")), write("s.toml", scenario_with("c.urdf"))), watch="new"),
    Case("info-planar-arm-joint", ("info", "p.urdf"), ("p.urdf", "joint 'arm_joint2' (JointModelPlanar) has 3 degrees of freedom", "revolute, continuous or prismatic"), write("p.urdf", _joint_type("planar", "arm_joint2"))),
    Case("info-floating-arm-joint", ("info", "f.urdf"), ("f.urdf", "joint 'arm_joint3' (JointModelFreeFlyer) has 6 degrees of freedom"), write("f.urdf", _joint_type("floating", "arm_joint3"))),
    # ---- 3. what a command allocates is checked first ------------------------------------
    Case("sweep-linspace-of-a-billion", ("sweep", "st.toml", "--out", "new"), ("st.toml", "parameter[0]", "linspace: 1000000000000 points", "GiB", "give fewer"), steps(write("base.toml", scenario_with(_URDF)), write("st.toml", '[study]\nbase = "base.toml"\nseed = 1\n[[parameter]]\npath = "water.current_world_m_s[0]"\nlinspace = [1, 1000, 1000000000000]\n')), watch="new"),
    Case("sweep-logspace-of-a-billion", ("sweep", "st.toml", "--out", "new"), ("logspace: 1000000000000 points",), steps(write("base.toml", scenario_with(_URDF)), write("st.toml", '[study]\nbase = "base.toml"\nseed = 1\n[[parameter]]\npath = "water.density_kg_m3"\nlogspace = [1000, 1030, 1000000000000]\n')), watch="new"),
    Case("sweep-too-many-samples", ("sweep", "st.toml", "--out", "new"), ("the study's 20000000000000 runs (2 points x 10000000000000 samples)", "split the study"), steps(write("base.toml", scenario_with(_URDF)), write("st.toml", '[study]\nbase = "base.toml"\nseed = 1\nsamples = 10000000000000\n[[parameter]]\npath = "water.current_world_m_s[0]"\nvalues = [0.0, 0.1]\n')), watch="new"),
    Case("compare-controllers-log-too-large", ("compare-controllers", "r.toml", "--out", "new", "--set", "scenario.duration_s=1e9", "--controllers", "ppc"), ("the log of this run", "GiB", "scenario.duration_s"), write("r.toml", realistic_with()), watch="new"),
    Case("compare-arms-duration-too-long", ("compare-arms", "r.toml", "--out", "new", "--duration", "1e9", "--arms", "reference"), ("the log of this run", "GiB"), write("r.toml", realistic_with()), watch="new"),
    # ---- 4. a controller that raises: the rollout kept, its traceback shown -------------
    Case("run-controller-raises-later", _RUN_NEW, ("run stopped", "compute() raised at t = 0.1", "ZeroDivisionError", "partial rollout (t = 0 to 0.1"), _with_controller(_controller("if t > 0.1:\n    return 1 / 0\nreturn np.zeros(self.nv)")), code=3, traceback_of="ctrl.py", after=rollout_kept("new", "error", error="ZeroDivisionError", error_traceback="ctrl.py")),
    Case("run-controller-reset-raises", _RUN_NEW, ("run stopped", "reset() raised at t = 0 s", "RuntimeError: no hardware"), _with_controller(_controller("return np.zeros(self.nv)") + "\n    def reset(self):\n        raise RuntimeError('no hardware')\n"), code=3, traceback_of="ctrl.py", after=rollout_kept("new", "error")),
    Case("run-controller-signals-raise", _RUN_NEW, ("signals() raised", "KeyError"), _with_controller(_controller("return np.zeros(self.nv)") + "\n    def signals(self):\n        return {}['e_x']\n"), code=3, traceback_of="ctrl.py", after=rollout_kept("new", "error")),
    Case("run-controller-returns-a-wrong-size", _RUN_NEW, ("run stopped", "controller returned an invalid tau"), _with_controller(_controller("return np.zeros(3)")), code=3, after=rollout_kept("new", "SimulationError")),
    Case("run-controller-constructor-raises", _RUN_NEW, ("s.toml", "[controller]", "rejected its parameters (gain)", "KeyError"), _with_controller(_controller("return None", init="self.gain = {}['gain']"), "gain = 2.0\n"), traceback_of="ctrl.py", watch="new"),
    Case("run-controller-module-fails-to-import", _RUN_NEW, ("importing 'ctrl' failed", "NameError"), _with_controller("import numpy as np\nundefined_name\n"), traceback_of="ctrl.py", watch="new"),
    # ---- 5. a second Ctrl-C while the first is handled -----------------------------------
    # which message ends the run depends on whether the second press lands during the save
    # (a race on a loaded machine); test_run_outputs.py holds both outcomes at set delays
    Case("run-second-ctrl-c-while-saving", ("run", "long.toml", "--out", "new", "--quiet"), ("interrupted",), write("long.toml", scenario_with(_URDF, 600.0)), code=130, interrupts=(0.02,), after=rollout_kept("new", "interrupted")),
    Case("run-three-ctrl-c-in-a-row", ("run", "long.toml", "--out", "new", "--quiet"), ("interrupted",), write("long.toml", scenario_with(_URDF, 600.0)), code=130, interrupts=(0.01, 0.05), after=rollout_kept("new", "interrupted")),
    # ---- 6. seeds numpy would refuse: named where they are given -------------------------
    Case("run-negative-seed", ("run", "{good}", "--out", "new", "--set", "scenario.seed=-5"), ("override 'scenario.seed'", "must be an integer in [0, 2^63 - 1], got -5"), watch="new"),
    Case("run-seed-beyond-int64", ("run", "{good}", "--out", "new", "--set", "scenario.seed=9223372036854775808"), ("scenario.seed", "[0, 2^63 - 1]"), watch="new"),
    Case("run-fractional-seed", ("run", "{good}", "--out", "new", "--set", "scenario.seed=1.5"), ("scenario.seed", "must be an integer, got 1.5"), watch="new"),
    Case("run-negative-sea-seed", ("run", "sea.toml", "--out", "new", "--set", "water.sea.seed=-1"), ("override 'water.sea.seed'", "got -1"), write("sea.toml", _SEA), watch="new"),
    Case("run-negative-seed-in-the-file", ("run", "s.toml", "--out", "new"), ("s.toml: scenario.seed", "got -3"), write("s.toml", scenario_with(_URDF).replace("seed = 1", "seed = -3")), watch="new"),
    Case("sweep-negative-study-seed", ("sweep", "st.toml", "--out", "new"), ("st.toml: study.seed", "got -1"), steps(write("base.toml", scenario_with(_URDF)), write("st.toml", '[study]\nbase = "base.toml"\nseed = -1\n[[parameter]]\npath = "water.current_world_m_s[0]"\nvalues = [0.0, 0.1]\n')), watch="new"),
    Case("sweep-negative-fixed-seed", ("sweep", "st.toml", "--out", "new"), ("st.toml", "study.base with [fixed]", "scenario.seed", "got -2"), steps(write("base.toml", scenario_with(_URDF)), write("st.toml", '[study]\nbase = "base.toml"\nseed = 1\n[fixed]\n"scenario.seed" = -2\n[[parameter]]\npath = "water.current_world_m_s[0]"\nvalues = [0.0, 0.1]\n')), watch="new"),
    # ---- 7. every count bounded --------------------------------------------------------
    Case("run-sea-of-ten-million-components", ("run", "sea.toml", "--out", "new", "--set", "water.sea.n_components=10000000"), ("override 'water.sea.n_components'", "must be <= 2000, got 10000000"), write("sea.toml", _SEA), watch="new"),
    Case("run-sea-of-no-component", ("run", "sea.toml", "--out", "new", "--set", "water.sea.n_components=0"), ("water.sea.n_components", "must be >= 1, got 0"), write("sea.toml", _SEA), watch="new"),
    Case("sweep-workers-beyond-the-machine", ("sweep", "{study}", "--out", "study_out", "--workers", "100000"), ("--workers", "must be an integer <=", "per CPU", "100000"), watch="study_out"),
    Case("compare-controllers-jobs-beyond-the-machine", ("compare-controllers", "{good}", "--out", "new", "--jobs", "100000"), ("--jobs", "per CPU"), watch="new"),
    Case("compare-arms-jobs-beyond-the-machine", ("compare-arms", "{good}", "--out", "new", "--jobs", "100000"), ("--jobs", "per CPU"), watch="new"),
    Case("compare-arms-ik-starts-beyond-reason", ("compare-arms", "{good}", "--out", "new", "--ik-starts", "100000000"), ("--ik-starts", "must be an integer <= 10000"), watch="new"),
    # ---- 8. an empty path is a missing value, not the current directory ------------------
    Case("run-empty-out", ("run", "{good}", "--out", ""), ("argument --out", "must be a path, got ''"), watch="."),
    Case("run-blank-out", ("run", "{good}", "--out", "  "), ("--out", "must be a path"), watch="."),
    Case("run-empty-scenario", ("run", "", "--out", "new"), ("argument scenario", "must be a path"), watch="new"),
    Case("sweep-empty-out", ("sweep", "{study}", "--out", ""), ("--out", "must be a path"), watch="."),
    Case("compare-controllers-empty-out", ("compare-controllers", "{good}", "--out", ""), ("--out", "must be a path"), watch="."),
    Case("compare-arms-empty-out", ("compare-arms", "{good}", "--out", ""), ("--out", "must be a path"), watch="."),
    Case("validate-empty-out", ("validate", "pool", _DATA, "--out", ""), ("--out", "must be a path"), watch="."),
    Case("validate-empty-trials", ("validate", "pool", _DATA, "--out", "new", "--trials", ""), ("--trials", "must be trial names"), watch="new"),
    Case("validate-an-empty-trial-name", ("validate", "pool", _DATA, "--out", "new", "--trials", "_alt_011-1,"), ("--trials", "none empty"), watch="new"),
    Case("replay-empty-out", ("replay", "prior", "--html", "--out", ""), ("--out", "must be a path"), watch="."),
    Case("replay-empty-urdf", ("replay", "prior", "--html", "--urdf", ""), ("--urdf", "must be a path"), watch="."),
    Case("info-empty", ("info", ""), ("argument urdf", "must be a path"), watch="."),
    Case("report-empty", ("report", ""), ("argument directory", "must be a path"), watch="."),
    Case("sweep-empty-scheduler", ("sweep", "{study}", "--out", "new", "--scheduler", ""), ("--scheduler", "must be an address"), watch="new"),
    Case("run-empty-model", ("run", "s.toml", "--out", "new"), ("s.toml: scenario.model: the model is empty",), write("s.toml", scenario_with("")), watch="new"),
    Case("sweep-empty-base", ("sweep", "st.toml", "--out", "new"), ("st.toml: study.base: is empty",), write("st.toml", '[study]\nbase = ""\nseed = 1\n[[parameter]]\npath = "water.current_world_m_s[0]"\nvalues = [0.0, 0.1]\n'), watch="new"),
    # ---- 9. keys inside arrays of tables; a table value replaces a whole table ----------
    Case("run-thruster-index-out-of-range", ("run", "r.toml", "--out", "new", "--set", "actuation.thruster[9].max_forward_N=0"), ("override 'actuation.thruster[9].max_forward_N'", "index 9 out of range, 'actuation.thruster' has 4 entries"), write("r.toml", realistic_with()), watch="new"),
    Case("run-thruster-key-misspelled", ("run", "r.toml", "--out", "new", "--set", "actuation.thruster[0].max_forwrd_N=0"), ("unknown key 'actuation.thruster[0].max_forwrd_N'", "did you mean 'actuation.thruster[0].max_forward_N'?"), write("r.toml", realistic_with()), watch="new"),
    Case("run-thruster-negative-limit", ("run", "r.toml", "--out", "new", "--set", "actuation.thruster[0].max_forward_N=-1"), ("override 'actuation.thruster[0].max_forward_N'", ">= 0"), write("r.toml", realistic_with()), watch="new"),
    Case("run-whole-table-given-a-number", ("run", "{good}", "--out", "new", "--set", "controller=3"), ("override 'controller'", "is a whole table; give a table value"), watch="new"),
    Case("run-whole-controller-table-bad-type", ("run", "{good}", "--out", "new", "--set", 'controller={{type="nope"}}'), ("override 'controller'", "controller.type: must be one of"), watch="new"),
    Case("run-whole-controller-table-unknown-key", ("run", "{good}", "--out", "new", "--set", 'controller={{type="none", tpe=1}}'), ("override 'controller'", "unknown key 'controller.tpe'", "did you mean 'controller.type'?"), watch="new"),
    Case("run-whole-thruster-table-incomplete", ("run", "r.toml", "--out", "new", "--set", 'actuation.thruster[0]={{name="x"}}'), ("override 'actuation.thruster[0]'", "position_body_m: is required"), write("r.toml", realistic_with()), watch="new"),
    Case("run-index-into-a-table", ("run", "{good}", "--out", "new", "--set", "water[0].density_kg_m3=1000"), ("'water' is not a list in the file",), watch="new"),
    Case("sweep-thruster-path-out-of-range", ("sweep", "st.toml", "--out", "new"), ("st.toml", "parameter[0] 'actuation.thruster[7].max_forward_N'", "index 7 out of range"), steps(write("base.toml", realistic_with()), write("st.toml", '[study]\nbase = "base.toml"\nseed = 1\n[[parameter]]\npath = "actuation.thruster[7].max_forward_N"\nvalues = [1.0, 2.0]\n')), watch="new"),
    # ---- 10. nothing silently capped: validate's --step ------------------------------------
    Case("validate-step-longer-than-every-interval", ("validate", "pool", _DATA, "--out", "new", "--trials", "_alt_011-1", "--step", "10"), ("--step 10 s is longer than the longest IMU interval", "a single step of its own length"), watch="new"),
    Case("validate-step-absurdly-small", ("validate", "pool", _DATA, "--out", "new", "--trials", "_alt_011-1", "--step", "1e-9"), ("RK4 steps over the 1 trials", "more than 1e+07"), watch="new"),
    Case("validate-step-zero", ("validate", "pool", _DATA, "--out", "new", "--step", "0"), ("argument --step", "must be positive"), watch="new"),
    Case("validate-step-nan", ("validate", "pool", _DATA, "--out", "new", "--step", "nan"), ("argument --step", "finite"), watch="new"),
    Case("validate-out-is-a-file", ("validate", "pool", _DATA, "--out", "f", "--trials", "_alt_011-1"), ("--out f", "is a file"), write("f", "mine"), watch="f"),
    Case("validate-unknown-trial", ("validate", "pool", _DATA, "--out", "new", "--trials", "_alt_999-9"), ("no trial named _alt_999-9",), watch="new"),
    # ---- 11. a degenerate model refused; a divergence says what diverged and where -----
    Case("info-zero-joint-axis", ("info", "z.urdf"), ("z.urdf", "joint 'arm_joint2'", "is zero"), write("z.urdf", urdf_with(**{'<axis xyz="0 1 0"/>': '<axis xyz="0 0 0"/>'}))),
    Case("run-zero-joint-axis", ("run", "s.toml", "--out", "new"), ("z.urdf", "joint 'arm_joint2'", "<axis xyz=\"0 0 0\"> is zero"), steps(write("z.urdf", urdf_with(**{'<axis xyz="0 1 0"/>': '<axis xyz="0 0 0"/>'})), write("s.toml", scenario_with("z.urdf"))), watch="new"),
    Case("run-current-of-1400-m-s", ("run", "{good}", "--out", "new", "--quiet", "--set", "water.current_world_m_s=[1400, 0, 0]"), ("run stopped: simulation diverged between t = 0 s and", "water speed at the vehicle = 1.4e+03 m/s"), code=3, after=rollout_kept("new", "SimulationError")),
    Case("run-disturbance-of-1e30", ("run", "r.toml", "--out", "new", "--quiet", "--set", "disturbance.amplitude=[1e30, 0, 0, 0, 0, 0]"), ("simulation diverged", "disturbance vehicle fx = 1.8e+27 N"), write("r.toml", realistic_with()), code=3, after=rollout_kept("new", "SimulationError")),
    Case("run-torque-of-1e30", _RUN_NEW, ("simulation diverged", "applied generalized force arm_joint2 = 1e+30 N m"), _with_controller(_controller("tau = np.zeros(self.nv)\ntau[7] = 1e30\nreturn tau")), code=3, after=rollout_kept("new", "SimulationError")),
    # ---- 12. plausibility: refused where no body or water can be that, warned where unusual --
    Case("info-volume-in-litres", ("info", "l.urdf"), ("l.urdf", "the body on joint 'root_joint' (links base_link)", "cannot be physical", "a <volume> in litres?"), write("l.urdf", urdf_with(**{'<volume value="0.010862"': '<volume value="10.862"'}))),
    Case("info-mass-in-grams", ("info", "g.urdf"), ("g.urdf", "mean density of", "cannot be physical", "a <mass> in grams?"), write("g.urdf", urdf_with(**{'<mass value="11"/>': '<mass value="11000"/>'}))),
    Case("info-duplicate-volume", ("info", "d.urdf"), ("d.urdf", "link 'base_link'", "<hydrodynamics> has 2 <volume> elements"), write("d.urdf", urdf_with(**{'<volume value="0.010862"/>': '<volume value="0.010862"/><volume value="0.02"/>'}))),
    Case("info-duplicate-mass", ("info", "m.urdf"), ("m.urdf", "<inertial> has 2 <mass> elements"), write("m.urdf", urdf_with(**{'<mass value="11"/>': '<mass value="11"/><mass value="12"/>'}))),
    Case("info-water-density-in-grams", ("info", "{urdf}", "--water-density", "1025000"), ("water_density_kg_m3 = 1.025e+06 kg/m^3 cannot be physical",)),
    Case("run-water-density-in-grams", ("run", "{good}", "--out", "new", "--set", "water.density_kg_m3=1025000"), ("override 'water.density_kg_m3'", "cannot be physical", "sea water is 1025 kg/m^3"), watch="new"),
    Case("run-wave-period-in-microseconds", ("run", "{good}", "--out", "new", "--set", "water.waves.amplitude_m=0.1", "--set", "water.waves.period_s=1e-6"), ("override 'water.waves.period_s'", "cannot be physical", "milliseconds"), watch="new"),
    Case("run-breaking-wave", ("run", "{good}", "--out", "new", "--set", "water.waves.amplitude_m=20", "--set", "water.waves.period_s=8"), ("steeper than 1/7: it breaks",), watch="new"),
    Case("run-current-faster-than-sound", ("run", "{good}", "--out", "new", "--set", "water.current_world_m_s=[2000, 0, 0]"), ("override 'water.current_world_m_s'", "2000 m/s cannot be physical"), watch="new"),
    Case("run-integrator-step-of-a-nanosecond", ("run", "{good}", "--out", "new", "--quiet", "--set", "integrator.step_s=1e-9", "--set", "scenario.duration_s=1e-6", "--set", "output.log_period_s=1e-6"), ("warning: override 'integrator.step_s': 1e-09 s is far outside",), code=0, after=rollout_kept("new", "ok")),
    Case("run-fresh-water-density-warned", ("run", "{good}", "--out", "new", "--quiet", "--set", "water.density_kg_m3=1240"), ("warning: override 'water.density_kg_m3': 1240 kg/m^3 is far outside fresh to sea water",), code=0, after=rollout_kept("new", "ok")),
    # ---- 13. a model entry that names no model says why ------------------------------
    Case("info-a-directory", ("info", "adir"), ("'adir' is a directory", "not a URDF file"), steps(lambda d: (d / "adir").mkdir())),
    Case("info-a-near-miss-of-a-shipped-name", ("info", "bluerov3"), ("'bluerov3' is neither a file", "nor a shipped model (bluerov2_heavy,", "did you mean 'bluerov2_heavy'?")),
    Case("info-not-a-urdf-file", ("info", "notes.txt"), ("notes.txt", "not well-formed XML"), write("notes.txt", "my notes\n")),
    Case("run-model-is-a-directory", ("run", "s.toml", "--out", "new"), ("s.toml: scenario.model", "'adir' is a directory"), steps(lambda d: (d / "adir").mkdir(), write("s.toml", scenario_with("adir"))), watch="new"),
    Case("run-model-is-not-a-urdf-file", ("run", "s.toml", "--out", "new"), ("notes.txt", "not well-formed XML"), steps(write("notes.txt", "my notes\n"), write("s.toml", scenario_with("notes.txt"))), watch="new"),
    Case("run-model-near-miss", ("run", "s.toml", "--out", "new"), ("scenario.model", "'uvms_lbv15' is neither a file", "did you mean 'uvms_lbv150'?"), write("s.toml", scenario_with("uvms_lbv15")), watch="new"),
    # ---- 15. compare-arms: --set and --quiet, nothing ran, a vehicle without an arm -------
    Case("compare-arms-vehicle-without-an-arm", ("compare-arms", "v.toml", "--out", "new"), ("v.toml", "is a vehicle without an arm", "give a scenario whose model carries an arm"), write("v.toml", scenario_with("lbv150").replace("joint_positions_rad = [0.0, 0.5, -0.5, 0.0]", "").replace("velocity = [0.2, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]", "")), watch="new"),
    Case("compare-arms-no-arm-ran", ("compare-arms", "{good}", "--out", "new", "--quiet", "--arms", "notarm.urdf"), ("compare-arms: no arm ran, nothing is compared", "notarm: model error"), write("notarm.urdf", '<robot name="x"><link name="a"/></robot>'), code=3, after=_first_row_is("new/comparison.csv", "notarm,")),
    Case("compare-arms-bad-set", ("compare-arms", "{good}", "--out", "new", "--set", "water.curent_world_m_s=[0,0,0]"), ("override 'water.curent_world_m_s'", "did you mean 'water.current_world_m_s'?"), watch="new"),
    Case("compare-arms-set-not-an-assignment", ("compare-arms", "{good}", "--out", "new", "--set", "scenario.duration_s"), ("override 'scenario.duration_s': expected KEY=VALUE",), watch="new"),
    # ---- 16. wrench components no thruster produces: said once, with what was dropped ----
    Case("run-allocation-drops-roll-and-pitch", ("run", "r.toml", "--out", "new", "--quiet"), ("warning: the thrusters cannot produce every wrench component", "of pitch moment my", "actuation.allocated_components = [0, 1, 2, 5]"), write("r.toml", realistic_with().replace("allocated_components = [0, 1, 2, 5]\n", "")), code=0, after=rollout_kept("new", "ok")),
    # ---- 17. a rerun into the same directory (make demo's) replaces the outputs -----------
    Case("run-again-into-the-same-directory", ("run", "{good}", "--out", "prior", "--quiet", "--html", "--overwrite"), (), code=0, watch="study_out", after=rollout_kept("prior", "ok")),
    # ---- 18. a controller set in code is recorded as what ran (the Python API) ----------
    Case("api-controller-set-in-code-is-recorded", ("s.toml", "new"), (), steps(write("api.py", _SET_IN_CODE), write("s.toml", scenario_with(_URDF))), code=0, script="api.py", watch="prior", after=_recorded_as_set_in_code),
    # ---- 1. the Gymnasium observation is the policy's own array (the Python API) -------
    Case("api-gym-observation-written-by-the-policy", (), (), write("gym_meddler.py", _GYM_MEDDLER), code=0, script="gym_meddler.py", watch="prior"),
    # ---- 14. a full disk: exit 4, the file named, what was kept said --------------------
    Case("run-disk-full-at-a-figure", ("velocities.png", "run", "s.toml", "--out", "new", "--quiet"), ("cannot write new/velocities.png: No space left on device", "kept in new: rollout.npz, rollout.json, metrics.json, pose.png"), steps(write("diskfull.py", DISK_FULL), write("s.toml", scenario_with(_URDF))), code=4, script="diskfull.py", after=rollout_kept("new", "ok")),
    Case("run-disk-full-at-the-rollout", ("rollout.npz", "run", "s.toml", "--out", "new", "--quiet"), ("cannot write new/rollout.npz: No space left on device", "nothing of this run was kept in new"), steps(write("diskfull.py", DISK_FULL), write("s.toml", scenario_with(_URDF))), code=4, script="diskfull.py", watch="new"),
    Case("run-disk-full-at-the-metadata", ("rollout.json", "run", "s.toml", "--out", "new", "--quiet"), ("cannot write new/rollout.json", "nothing of this run was kept"), steps(write("diskfull.py", DISK_FULL), write("s.toml", scenario_with(_URDF))), code=4, script="diskfull.py", watch="new"),
    Case("replay-disk-full", ("replay.html", "replay", "prior", "--html"), ("prior/replay.html: No space left on device",), write("diskfull.py", DISK_FULL), code=4, script="diskfull.py"),
    Case("sweep-disk-full", ("results.parquet", "sweep", "{study}", "--out", "new", "--workers", "0", "--quiet"), ("new/results.parquet: No space left on device",), write("diskfull.py", DISK_FULL), code=4, script="diskfull.py", watch="prior"),
    # ---- the free surface (issue 21): its keys, its stop, a hull that cannot be built ---
    Case("run-free-surface-not-a-boolean", ("run", _SURFACING, "--out", "new", "--set", "water.free_surface=1"), ("override 'water.free_surface'", "must be true or false, got 1"), watch="new"),
    Case("run-stop-at-surface-a-string-in-the-file", ("run", "s.toml", "--out", "new"), ("s.toml", "water.stop_at_surface", "must be true or false, got 'yes'"), write("s.toml", scenario_with(_URDF).replace("[water]\n", '[water]\nstop_at_surface = "yes"\n')), watch="new"),
    Case("run-free-surface-key-misspelled", ("run", _SURFACING, "--out", "new", "--set", "water.free_surfce=true"), ("unknown key 'water.free_surfce'", "did you mean 'water.free_surface'?"), watch="new"),
    Case("run-stop-at-surface-reached", ("run", _SURFACING, "--out", "new", "--quiet", "--set", "water.stop_at_surface=true", "--set", "initial.position_world_m=[0, 0, -0.3]"), ("run stopped: link 'base_link' reached the free surface at t =", "([water] stop_at_surface)", "the partial rollout (t = 0 to"), code=3, after=rollout_kept("new", "SimulationError")),
    Case("run-stop-at-surface-above-it-at-the-start", ("run", _SURFACING, "--out", "new", "--quiet", "--set", "water.stop_at_surface=true", "--set", "initial.position_world_m=[0, 0, 1]"), ("reached the free surface at t = 0 s", "1 m above the surface", "nothing was simulated"), code=3, after=rollout_kept("new", "SimulationError")),
    Case("info-flat-mesh-as-a-hull", ("info", "h.urdf"), ("h.urdf", "link 'base_link'", "cannot use <mesh> as a hull", "flat.stl' encloses no volume", "a sphere of the link's volume instead"), steps(write("flat.stl", _FLAT_STL), write("h.urdf", urdf_with(**{_BASE_BOX: _FLAT_MESH}))), code=0),
    Case("info-zero-box-as-a-hull", ("info", "h.urdf"), ("h.urdf", "link 'base_link'", "cannot use <box> as a hull", "got 0.0"), write("h.urdf", urdf_with(**{_BASE_BOX: '<geometry><box size="0.53 0.245 0"/></geometry>'})), code=0),
    Case("info-derived-body-of-a-flat-mesh", ("info", "d.urdf"), ("d.urdf", "link 'arm_link1'", "cannot derive hydrodynamics from <mesh>", "encloses no volume"), steps(write("flat.stl", _FLAT_STL), write("d.urdf", _arm_link1_derived_from(_FLAT_MESH)))),
    Case("run-derived-body-of-a-flat-mesh", ("run", "s.toml", "--out", "new"), ("d.urdf", "link 'arm_link1'", "encloses no volume"), steps(write("flat.stl", _FLAT_STL), write("d.urdf", _arm_link1_derived_from(_FLAT_MESH)), write("s.toml", scenario_with("d.urdf"))), watch="new"),
]  # fmt: skip
