#!/usr/bin/env python3
"""Logs of motulator's induction machine for the ladder's third-party guard.

The drive monitor's `sim-host explain --ladder` is judged on logs that nobody on the project
simulated: this script makes them with motulator (Aalto University's open-source drive
simulator, the version pinned in requirements.txt), writes each as a CSV in the monitor's
log schema with 12-bit sensors, writes the parameter file a USER would have for each machine
(nameplate, DC resistance, no-load and locked-rotor tests: never the simulator's truth), and
a manifest with the hidden effects, their true sizes and the machines' true values. The guard
is `sim-host/tests/cli/ladder_third_party.rs`; README.md beside this file says how to run it.
The user-law logs (issue 85, `USER_LAW_LOGS`) hide laws the monitor's library lacks, each
with the law file a user would write for it (`laws/`) and, for the foreign magnetising
curve, the machine's no-load test table.

    python3 -m venv /tmp/mvenv && /tmp/mvenv/bin/pip install -r requirements.txt
    /tmp/mvenv/bin/python generate.py            # all logs into sim-host/tests/data/motulator
    /tmp/mvenv/bin/python generate.py --only kw2p2_fan --out /tmp/x

With --only, the logs not named keep the entries the manifest on disk holds (and so do the
machines whose parameter file comes out the same: the tests' readings differ in their last
digits from one CPU to another); without such a manifest (another --out) none is written.

What motulator does and what this script does
---------------------------------------------
- The machine is motulator's `InductionMachine` (the Gamma-equivalent model, flux linkages as
  states; main-flux saturation through a callable stator inductance `L_s(|psi_s|)`), with
  parameters from motulator's `InductionMachinePars.from_inv_gamma_model_pars`. The
  mechanics are motulator's `StiffMechanicalSystem` (`B_L(|w_M|) w_M + tau_L(t)`: a fan is
  `B_L = k |w_M|`, dry friction `B_L = T_c tanh(|w_M|/w_0)/|w_M|`), or its
  `ExternalRotorSpeed` for the locked-rotor test.
- A load law of the shaft's angle (the user-law logs): motulator's mechanics take loads of
  t and w only, so `ShaftWithAngle` (a motulator `Subsystem` written here) holds the speed
  and the shaft's mechanical angle as states, J dw_M/dt = tau_M - b w_M - T_L(t, w_M,
  theta_M), dtheta_M/dt = w_M, theta_M = 0 at t = 0: a compressor t0 + a sin(k theta_M +
  phi) pulsing k times per revolution, a pump k |w_M|^n sign(w_M).
- A foreign magnetising curve: the same callable L_s(|psi_s|) of motulator's machine with a
  tanh curve psi = psi_sat tanh(L_u i_m / psi_sat) in place of the library's form
  (`tanh_l_s`: L_s = psi / i_m(psi), i_m = (psi_sat / L_u) atanh(psi / psi_sat)).
- Direct-on-line runs: motulator's `Drive` needs a converter, so the supply is an ideal
  three-phase source written here (`IdealSupply`, a motulator `Subsystem`) joined to the
  machine and the mechanics in a motulator `Model` (`DirectOnLine`); its right-hand side
  (`Model.rhs`, motulator's own) is integrated by scipy's `solve_ivp` (DOP853, rtol = atol =
  1e-9) segment by segment between the supply and load steps, sampled at the log's rate.
- The V/f log: motulator's own `Drive` with its `VoltageSourceConverter` (stiff DC bus), its
  `VHzControl` and its `Simulation`, with the average converter model (motulator's
  zero-order hold of the duty ratios, here handed to the solver as two half periods so that
  the middle of every hold is a solver point: see `half_period_zoh`). The log samples the
  middle of each hold, where the held voltage equals the reference the control rotated for
  its delay; `t_s` counts from the first sample.
- A winding that heats: motulator's machine reads `par.R_s` and `par.R_r` at every
  right-hand-side call, so `HeatedMachine` (a subclass) sets them from the time in
  `set_outputs(t)`, which motulator calls before each `rhs`.

The logs (the list `LOGS` below; rates, sizes and hashes in manifest.toml after a run)
--------------------------------------------------------------------------------------
Three machines: motulator's 2.2 kW example machine (its published inverse-Gamma values and
motulator's saturation law of the same machine, Qu et al. 2012), the 7.5 kW (10 hp) 400 V
50 Hz preset of MATLAB/Simscape's asynchronous machine as transcribed by the Modelica
Buildings library (`IM_10HP_400V_50Hz`), and Krause, Wasynczuk and Sudhoff's 50 hp (37 kW)
460 V 60 Hz machine (Analysis of Electric Machinery and Drive Systems). Each log starts
direct-on-line from standstill (but the V/f log, which starts from standstill under V/f
control); "variac" steps the supply voltage down 15 %, up to +10 % and back. See `LOGS`.

The user-law logs (`USER_LAW_LOGS`, manifest.toml's [[user_law_log]]): a compressor pulsing
once (2.2 kW) and twice (7.5 kW) per revolution, a pump k |w|^2.7 (7.5 kW), and the 2.2 kW
machine with a tanh magnetising curve; the law files a user would write (`UserLaw`: starts
25-60 % off the truth, `check_starts`) into `laws/`, and the no-load test table
(`noload_table`: the shaft free, 30 % to 120 % of the rated voltage at rated frequency, RMS
line voltage and phase current to 4 significant digits, `v_ll_rms_V,i0_rms_A`).

The user's parameter file (`ieee112_file`)
------------------------------------------
As a user makes it from the nameplate and the tests of IEEE Std 112 (the no-load and
locked-rotor tests and the DC resistance), each test run on the motulator machine itself:
- nameplate: rated voltage, frequency, poles (`[supply]`, `poles`);
- DC test: `rs_ohm` = the cold stator resistance per phase (exact: a bridge reading);
- locked-rotor test: rotor held (`ExternalRotorSpeed` at 0), rated frequency, the voltage
  lowered until the current is the rated current; from V, I and P per phase:
  `R_LR = P / I^2`, `X_LR = sqrt((V/I)^2 - R_LR^2)`, `rr_ohm = R_LR - rs_ohm`, and the
  leakage reactance split between stator and rotor by the NEMA design letter (IEEE 112's
  table: design A and D 50/50, design B 40/60);
- no-load test: rated voltage and frequency, no load (the machine's own friction only); from
  V, I, P: `X_NL = Q / I^2` per phase (`Q = sqrt(S^2 - P^2)`), `X_m = X_NL - X_1`, so `lm_h`
  is the rated-point value, saturation included where the machine saturates; the no-load
  loss balance `P - 3 I^2 rs` over the no-load speed squared gives `b_nms` (a viscous
  coefficient for the rotational loss);
- `j_kgm2` from the datasheet (the machine's value or a few per cent off: `J_DATASHEET`),
  `bl_nms = 0` (a user does not know the load as a viscous coefficient).
The readings and the reduction are written into manifest.toml, with each file key's distance
from the truth.

Sensors: 12-bit converters, voltage range +/- 1.5 x the rated peak phase voltage (rounded
up to 50 V), current range +/- 2 x the locked-rotor peak current at rated voltage (rounded up
to 5 A; the drive monitor's own convention, crates/monitor-io/src/params/sensors.rs), each
reading with Gaussian noise of one LSB before rounding; the speed (a computed speed, as the
monitor's own simulator writes it) with 0.02 rad/s of noise, to 1 mrad/s.
"""

from __future__ import annotations

import argparse
import hashlib
import importlib.metadata
import json
import math
import pathlib
import time
import tomllib
from dataclasses import dataclass, field
from types import SimpleNamespace

import numpy as np
from scipy.integrate import solve_ivp

import motulator.drive.control.im as control
from motulator.common.model import Model, Subsystem
from motulator.common.utils import abc2complex, complex2abc
from motulator.drive import model
from motulator.drive.utils import (
    BaseValues, InductionMachineInvGammaPars, InductionMachinePars,
    NominalValues, Sequence)

MOTULATOR = importlib.metadata.version("motulator")
REPO = pathlib.Path(__file__).resolve().parents[2]
OUT = REPO / "sim-host" / "tests" / "data" / "motulator"

# The dynamics effects of the monitor's effect library: the full-order machine every real
# machine is. Allowed on every log here (each has a start from standstill).
DYNAMICS = ["flux_dynamics", "current_dynamics", "d_axis_dynamics",
            "cross_coupling_dynamics"]

ALPHA_CU = 0.00393  # copper's temperature coefficient of resistance at 20 degC [1/K]
BITS = 12


# --------------------------------------------------------------------------- machines
@dataclass
class Machine:
    """A machine's truth: its T-equivalent circuit referred to the stator (ohm, H)."""

    name: str
    title: str
    source: str
    v_ll: float
    f_hz: float
    poles: int
    rs: float
    rr: float
    lls: float
    llr: float
    lm: float
    j: float
    b: float  # the machine's own viscous friction [N m s/rad] (an assumption, see source)
    p_rated_w: float
    design: str  # NEMA design letter the user's test report splits the leakage by
    j_datasheet_factor: float  # the datasheet's J over the true J
    i_rated_a: float | None = None  # a published nameplate current, else computed
    t_rated_nm: float | None = None  # a published rated torque, else computed
    saturation: dict | None = None  # Gamma L_s(psi) = L_su / (1 + (psi/psi_k)^S)
    # A foreign magnetising curve (not of the monitor's library form), Gamma model:
    # psi(i_m) = psi_s tanh(L_u i_m / psi_s), so L_s(psi) = psi / i_m(psi) with
    # i_m(psi) = (psi_s / L_u) atanh(psi / psi_s).
    tanh_curve: dict | None = None

    @property
    def n_p(self) -> int:
        return self.poles // 2

    @property
    def w_s(self) -> float:
        return 2 * math.pi * self.f_hz

    @property
    def u_peak(self) -> float:
        """Rated peak phase voltage [V]."""
        return math.sqrt(2 / 3) * self.v_ll

    def inv_gamma(self) -> dict:
        """The inverse-Gamma form (unique for the machine's terminal behaviour)."""
        ls, lr = self.lm + self.lls, self.lm + self.llr
        return {"R_s": self.rs, "R_R": self.rr * (self.lm / lr) ** 2,
                "L_sgm": ls - self.lm ** 2 / lr, "L_M": self.lm ** 2 / lr}

    def pars(self, sat: str | None = None) -> InductionMachinePars:
        """motulator's Gamma-model parameters, with a main-flux saturation law if asked:
        `sat` "qu2012" (motulator's law of the machine, `saturation`) or "tanh" (the
        foreign curve, `tanh_curve`)."""
        ig = InductionMachineInvGammaPars(n_p=self.n_p, **self.inv_gamma())
        par = InductionMachinePars.from_inv_gamma_model_pars(ig)
        if sat == "qu2012":
            s = self.saturation
            par.L_s = lambda psi, s=s: s["L_su"] / (1 + (psi / s["psi_k"]) ** s["S"])
        elif sat == "tanh":
            c = self.tanh_curve
            par.L_s = lambda psi, c=c: tanh_l_s(psi, c["psi_s"], c["L_u"])
        elif sat is not None:
            raise ValueError(f"unknown saturation law {sat!r}")
        return par

    def steady(self, slip: float, v_scale: float = 1.0) -> SimpleNamespace:
        """The T circuit's steady state at a slip (rated supply x v_scale)."""
        w = self.w_s
        v = v_scale * self.v_ll / math.sqrt(3)
        zr = self.rr / slip + 1j * w * self.llr
        zm = 1j * w * self.lm
        z = self.rs + 1j * w * self.lls + zm * zr / (zm + zr)
        i1 = v / z
        i2 = i1 * zm / (zm + zr)
        w_m = (1 - slip) * w / self.n_p
        p_mech = 3 * abs(i2) ** 2 * self.rr * (1 - slip) / slip
        return SimpleNamespace(i1=abs(i1), w_m=w_m, p_shaft=p_mech - self.b * w_m ** 2)

    def rated(self) -> SimpleNamespace:
        """Nameplate current, speed and torque at rated shaft power (bisection on slip)."""
        lo, hi = 1e-5, 0.3
        for _ in range(100):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if self.steady(mid).p_shaft < self.p_rated_w else (lo, mid)
        st = self.steady(0.5 * (lo + hi))
        return SimpleNamespace(
            slip=0.5 * (lo + hi), w_m=st.w_m,
            i=self.i_rated_a if self.i_rated_a is not None else st.i1,
            t=self.t_rated_nm if self.t_rated_nm is not None else self.p_rated_w / st.w_m)

    def ranges(self) -> tuple[float, float]:
        """Sensor ranges (+/-) [V], [A]: 1.5 x the peak phase voltage rounded up to 50 V;
        2 x the locked-rotor peak current rounded up to 5 A."""
        v = math.ceil(1.5 * self.u_peak / 50) * 50
        i_lr = self.steady(1.0).i1 * math.sqrt(2)
        return v, math.ceil(2 * i_lr / 5) * 5

    def truth_table(self) -> dict:
        return {"rs_ohm": self.rs, "rr_ohm": self.rr, "lls_h": self.lls,
                "llr_h": self.llr, "lm_h": self.lm, "ls_h": self.lm + self.lls,
                "lr_h": self.lm + self.llr, "poles": self.poles, "j_kgm2": self.j,
                "b_nms": self.b}


W60 = 2 * math.pi * 60
MACHINES = {
    "kw2p2": Machine(
        name="kw2p2", title="2.2 kW, 400 V, 50 Hz, 4 poles (motulator's example machine)",
        source=("motulator's 2.2 kW induction machine: its examples' inverse-Gamma values "
                "R_s 3.7 ohm, R_R 2.1 ohm, L_sgm 0.021 H, L_M 0.224 H, J 0.015 kg m^2, "
                "nominal 400 V 5 A 50 Hz 2.2 kW 14.6 N m; saturation law of the same "
                "machine from motulator's saturated-machine example (Qu, Ranta, Hinkkanen, "
                "Luomi, IEEE Trans. Ind. Appl. 2012): Gamma L_s = 0.34 / (1 + (0.84 "
                "psi_s)^7) H. The machine's own friction b = 0.005 N m s is assumed (as "
                "in examples/logs/motulator_2p2kw_dol)."),
        v_ll=400.0, f_hz=50.0, poles=4, rs=3.7, rr=2.1, lls=0.021, llr=0.0, lm=0.224,
        j=0.015, b=0.005, p_rated_w=2200.0, design="B", j_datasheet_factor=1.0,
        i_rated_a=5.0, t_rated_nm=14.6,
        saturation={"L_su": 0.34, "psi_k": 1 / 0.84, "S": 7.0},
        tanh_curve={"psi_s": 1.32, "L_u": 0.33}),
    "kw7p5": Machine(
        name="kw7p5", title="7.5 kW (10 hp), 400 V, 50 Hz, 4 poles (Simscape preset)",
        source=("MATLAB/Simscape asynchronous machine preset 10 hp (7.5 kW) 400 V 50 Hz as "
                "transcribed by the Modelica Buildings library (Buildings.Electrical.AC."
                "ThreePhasesBalanced.Loads.MotorDrive.InductionMotors.Data."
                "IM_10HP_400V_50Hz): Rs 0.7384 ohm, Rr 0.7402 ohm, Ls = Lr 0.127145 H, "
                "Lm 0.1241 H, J 0.0343 kg m^2. Rated current, speed and torque computed "
                "from the circuit at 7.5 kW; the machine's own friction b = 0.004 N m s is "
                "assumed."),
        v_ll=400.0, f_hz=50.0, poles=4, rs=0.7384, rr=0.7402, lls=0.127145 - 0.1241,
        llr=0.127145 - 0.1241, lm=0.1241, j=0.0343, b=0.004, p_rated_w=7500.0,
        design="B", j_datasheet_factor=1.04),
    "hp50": Machine(
        name="hp50", title="50 hp (37 kW), 460 V, 60 Hz, 4 poles (Krause's machine)",
        source=("Krause, Wasynczuk, Sudhoff, Analysis of Electric Machinery and Drive "
                "Systems: the 50 hp machine, rs 0.087 ohm, Xls = Xlr' 0.302 ohm, XM 13.08 "
                "ohm, rr' 0.228 ohm at 60 Hz, J 1.662 kg m^2. Rated current, speed and "
                "torque computed from the circuit at 37.3 kW; the machine's own friction "
                "b = 0.02 N m s is assumed."),
        v_ll=460.0, f_hz=60.0, poles=4, rs=0.087, rr=0.228, lls=0.302 / W60,
        llr=0.302 / W60, lm=13.08 / W60, j=1.662, b=0.02, p_rated_w=50 * 745.7,
        design="A", j_datasheet_factor=0.97),
}
# IEEE 112 / NEMA: the stator's share of the locked-rotor leakage reactance.
X1_SHARE = {"A": 0.5, "B": 0.4, "C": 0.3, "D": 0.5}

# Where the foreign curve's inverse i_m(psi) goes on in a straight line (psi/psi_s): a guard
# that keeps the current finite. The log's flux stays below it (checked in `simulate_dol`;
# 0.925 psi_s at most, the solver's trial stages included); the tests' inrush from zero flux
# goes beyond it at high voltage (1.04 psi_s at 120 %), which their readings, taken after
# 4 s in the steady state, do not see.
TANH_X_MAX = 0.995


def tanh_l_s(psi, psi_s, l_u):
    """The foreign curve's Gamma stator inductance L_s(|psi_s|) = psi / i_m(psi), with
    i_m(psi) = (psi_s / L_u) atanh(psi / psi_s) (psi = psi_s tanh(L_u i_m / psi_s)); L_u at
    psi = 0. Beyond psi / psi_s = TANH_X_MAX, i_m goes on along its tangent (finite for
    the solver's trial stages)."""
    x = np.abs(np.asarray(psi, dtype=float)) / psi_s
    xc = np.minimum(x, TANH_X_MAX)
    small = xc < 1e-6
    ratio = np.where(small, 1.0, xc / np.arctanh(np.where(small, 0.5, xc)))  # x / atanh x
    beyond = (x - xc) / (1 - TANH_X_MAX ** 2)  # the tangent's part, in units of psi_s/L_u
    i_scaled = np.where(x > TANH_X_MAX, np.arctanh(TANH_X_MAX) + beyond, 0.0)
    out = np.where(x > TANH_X_MAX, l_u * x / np.maximum(i_scaled, 1e-300), l_u * ratio)
    return float(out) if np.ndim(out) == 0 else out


# --------------------------------------------------------------------------- motulator parts
class IdealSupply(Subsystem):
    """An ideal three-phase voltage source: the stator voltage space vector u_ss(t)."""

    def __init__(self, u_ss):
        super().__init__()
        self.u_ss = u_ss

    def set_outputs(self, t):
        self.out.u_ss = self.u_ss(t)


class DirectOnLine(Model):
    """motulator's machine and mechanics on an ideal supply (no converter)."""

    def __init__(self, supply, machine, mechanics):
        super().__init__()
        self.supply, self.machine, self.mechanics = supply, machine, mechanics
        self.subsystems = [supply, machine, mechanics]

    def interconnect(self, _):
        self.machine.inp.u_ss = self.supply.out.u_ss
        self.mechanics.inp.tau_M = self.machine.out.tau_M
        self.machine.inp.w_M = self.mechanics.out.w_M


class HeatedMachine(model.InductionMachine):
    """motulator's induction machine whose R_s and R_r follow the time (a winding that
    heats): set before each right-hand side, which reads `par.R_s` and `par.R_r`."""

    def __init__(self, par, r_s, r_r):
        super().__init__(par)
        self._r_s, self._r_r = r_s, r_r

    def set_outputs(self, t):
        self.par.R_s, self.par.R_r = self._r_s(t), self._r_r(t)
        super().set_outputs(t)


class ShaftWithAngle(Subsystem):
    """A stiff shaft whose load torque is a law of the time, the speed and the shaft's
    mechanical angle (written here: motulator's mechanics take loads of t and w only):

        J dw_M/dt = tau_M - b w_M - T_L(t, w_M, theta_M),   dtheta_M/dt = w_M,

    with the angle a state, 0 at t = 0 (the log's start), integrated from the speed
    (not wrapped). b is the machine's own viscous friction."""

    def __init__(self, J, b, load):
        super().__init__()
        self.J, self.b, self.load = J, b, load
        self.state = SimpleNamespace(w_M=0.0, theta_M=0.0)
        self.sol_states = SimpleNamespace(w_M=[], theta_M=[])

    def set_outputs(self, t):
        w, theta = np.real(self.state.w_M), np.real(self.state.theta_M)
        self.out.w_M = w
        self.out.tau_L = self.load(t, w, theta)

    def rhs(self):
        w = self.out.w_M
        return [(np.real(self.inp.tau_M) - self.b * w - self.out.tau_L) / self.J, w]


def half_period_zoh(T_s, d_c_abc):
    """motulator's average converter model (a zero-order hold of the duty ratios over the
    sampling period, as `motulator.common.model.zoh`), handed to the solver as two half
    periods of the same switching-state vector, so that the middle of the hold is a point
    of the solution."""
    q = abc2complex(d_c_abc)
    return np.array([T_s / 2, T_s / 2]), np.array([q, q])


def friction(b: float, bl: float = 0.0, fan_k: float = 0.0, coulomb: tuple | None = None):
    """motulator's `B_L(|w_M|)`: viscous b + bl, a fan k |w|, dry friction T_c tanh(|w|/w_0)
    (B_L w_M is then T_c tanh(w_M/w_0), a smooth sign)."""

    def b_l(w_abs):
        out = b + bl + fan_k * w_abs
        if coulomb is not None:
            tc, w0 = coulomb
            x = np.maximum(w_abs / w0, 1e-12)
            out = out + tc / w0 * np.tanh(x) / x
        return out

    return b_l


def steps(points, initial):
    """Piecewise constant in time: `initial`, then each (t, value) from t on."""
    pts = sorted(points)

    def f(t):
        if np.ndim(t) == 0:
            v = initial
            for tp, vp in pts:
                if t >= tp:
                    v = vp
            return v
        v = np.full(np.shape(t), float(initial))
        for tp, vp in pts:
            v = np.where(t >= tp, vp, v)
        return v

    return f


# --------------------------------------------------------------------------- scenarios
@dataclass
class Log:
    """One log: its machine, scenario, hidden effects and what the manifest says of it."""

    name: str
    machine: str
    scenario: str
    duration_s: float
    hidden: list
    sizes: dict
    rate_hz: float = 2000.0
    drive: str = "dol"  # "dol" or "vf"
    variac: list = field(default_factory=list)  # (t, voltage factor)
    unbalance: tuple | None = None  # (fraction, angle_deg) of negative sequence
    bl_share: float = 0.0  # viscous load at rated speed, share of rated torque
    fan_share: float = 0.0  # fan torque at synchronous speed, share of rated torque
    fan_k: float | None = None  # fan coefficient [N m s^2] (overrides fan_share)
    coulomb_share: float = 0.0  # dry friction, share of rated torque
    coulomb_w0: float = 0.5  # [rad/s]
    torque_steps: list = field(default_factory=list)  # (t, share of rated torque)
    rs_factor: float = 1.0  # constant stator resistance over the file's (cold) value
    drift: dict | None = None  # {"rise_k", "tau_s", "rotor": bool}
    saturating: bool = False
    curve: str = "qu2012"  # the saturation law when saturating: "qu2012" or "tanh"
    vf_profile: list = field(default_factory=list)  # (t, speed reference in per unit)
    allowed: list = field(default_factory=list)
    equivalent: list = field(default_factory=list)  # (hidden, named, why)
    seed: int = 1
    # A load law the library lacks (the user-law logs): {"kind": "pulse", "order",
    # "t0_share", "a_share", "phi"} for t0 + a sin(order theta_m + phi), shares of rated
    # torque; {"kind": "power", "k", "n"} for k |w|^n sign(w) [N m (s/rad)^n]. On
    # `ShaftWithAngle`.
    load_law: dict | None = None
    law: "UserLaw | None" = None  # the user's law file for this log
    noload_table: str | None = None  # also write this machine's no-load table (CSV name)

    @property
    def sat(self) -> str | None:
        """The main-flux saturation law (None: a linear machine)."""
        return self.curve if self.saturating else None


@dataclass
class UserLaw:
    """A user's law file (issue 85's form): what a user writes knowing the physics but not
    the numbers. `parameters`: name -> (start, low, high, unit), written as literals here
    as a user would; `main` checks each start is 25-60 % off the truth and the truth inside
    the bounds."""

    file: str  # under laws/
    name: str
    acts_on: str
    comment: str
    expr: str | None = None
    parameters: dict = field(default_factory=dict)
    table: str | None = None  # relative to the laws file


COULOMB_EQ = ("coulomb_friction", "load_torque",
              "dry friction T_c tanh(w/w_0) at a speed that never reverses is a constant "
              "load torque once |w| >> w_0: the same term in J dw/dt = T_e - T_load")


def variac(t0):
    """The supply's voltage steps after a start that has settled by t0."""
    return [(t0 + 0.5, 0.85), (t0 + 1.5, 1.10), (t0 + 2.3, 1.0)]


LOGS = [
    Log("kw2p2_control", "kw2p2", "direct-on-line start, viscous load (80 % of rated "
        "torque at rated speed), variac steps", 4.0, [], {}, variac=variac(0.6),
        bl_share=0.8, seed=11),
    Log("kw2p2_saturation", "kw2p2", "direct-on-line start, viscous load 80 %, variac "
        "steps (-15 %, +10 %): the flux moves along the saturation curve", 4.0,
        ["saturation"], {}, variac=variac(0.6), bl_share=0.8, saturating=True, seed=12),
    Log("kw2p2_fan", "kw2p2", "direct-on-line start driving a fan (torque k w|w|, no "
        "viscous load), variac steps", 4.0, ["windage"], {}, variac=variac(0.6),
        fan_k=1.1 * 14.6 / (2 * math.pi * 50 / 2) ** 2, seed=13),
    Log("kw2p2_stator_drift", "kw2p2", "direct-on-line start, viscous load 80 %; the "
        "stator winding heats during the log (Rr unchanged)", 5.0, ["thermal_drift"],
        {}, bl_share=0.8, drift={"rise_k": 70.0, "tau_s": 3.0, "rotor": False},
        variac=[(2.5, 0.85), (3.5, 1.0)], seed=14),
    Log("kw2p2_long_warming", "kw2p2", "a long log at 2 kHz: direct-on-line start, "
        "viscous load 80 %, variac steps through 40 s; both windings warm by 50 K with a "
        "15 s time constant", 40.0, ["thermal_drift"], {}, bl_share=0.8,
        drift={"rise_k": 50.0, "tau_s": 15.0, "rotor": True},
        variac=[(12.0, 0.9), (13.5, 1.0), (26.0, 1.05), (27.5, 1.0)], seed=18),
    Log("kw2p2_long_control", "kw2p2", "the long log's control: direct-on-line start, "
        "viscous load 80 %, variac steps through 40 s, the windings at the file's "
        "temperature", 40.0, [], {}, bl_share=0.8,
        variac=[(12.0, 0.9), (13.5, 1.0), (26.0, 1.05), (27.5, 1.0)], seed=19),
    Log("kw2p2_unbalance", "kw2p2", "direct-on-line start, viscous load 80 %, variac "
        "steps, a negative-sequence supply", 4.0, ["supply_unbalance"], {},
        variac=variac(0.6), bl_share=0.8, unbalance=(0.03, -40.0), seed=15),
    Log("kw2p2_fan_saturation", "kw2p2", "direct-on-line start driving a fan, variac "
        "steps, a saturating machine", 4.0, ["windage", "saturation"], {},
        variac=variac(0.6), fan_k=1.1 * 14.6 / (2 * math.pi * 50 / 2) ** 2,
        saturating=True, seed=16),
    Log("kw2p2_vf_long", "kw2p2", "motulator's V/f control (VHzControl, average "
        "converter model, 650 V DC bus) from standstill: speed reference ramps and steps "
        "0 -> 0.5 -> 1.0 -> 0.7 -> 0.9 -> 0.3 per unit; dry friction and a viscous load "
        "(50 %); both windings heat", 22.0, ["thermal_drift", "coulomb_friction"], {},
        drive="vf", bl_share=0.5, coulomb_share=0.15,
        drift={"rise_k": 60.0, "tau_s": 8.0, "rotor": True},
        vf_profile=[(0.0, 0.0), (0.2, 0.0), (1.2, 0.5), (5.0, 0.5), (5.5, 1.0), (10.0, 1.0),
                    (10.3, 0.7), (15.0, 0.7), (15.2, 0.9), (19.0, 0.9), (20.0, 0.3),
                    (22.0, 0.3)],
        equivalent=[COULOMB_EQ], allowed=["load_torque"], seed=17),
    Log("kw7p5_warm_stator", "kw7p5", "direct-on-line start, viscous load 80 %, variac "
        "steps; the stator winding 20 % above the file's cold resistance throughout",
        4.0, ["warm_stator"], {}, variac=variac(0.6), bl_share=0.8, rs_factor=1.2,
        seed=21),
    Log("kw7p5_warm_unbalance", "kw7p5", "direct-on-line start, viscous load 80 %, "
        "variac steps; a warm stator (+20 %) and a negative-sequence supply", 4.0,
        ["warm_stator", "supply_unbalance"], {}, variac=variac(0.6), bl_share=0.8,
        rs_factor=1.2, unbalance=(0.025, 120.0), seed=22),
    Log("kw7p5_coulomb", "kw7p5", "direct-on-line start, dry friction (15 % of rated "
        "torque, smooth sign tanh(w/0.5 rad/s)) and a viscous load (50 %), variac steps",
        4.0, ["coulomb_friction"], {}, variac=variac(0.6), bl_share=0.5,
        coulomb_share=0.15, equivalent=[COULOMB_EQ], allowed=["load_torque"], seed=23),
    Log("hp50_control", "hp50", "direct-on-line start, viscous load 80 %, variac steps",
        5.0, [], {}, variac=variac(1.6), bl_share=0.8, seed=31),
    Log("hp50_load_step", "hp50", "direct-on-line start at no load; a constant load "
        "torque (not logged) of 40 % of rated from 2.0 s, stepping to 90 % at 3.5 s",
        5.0, ["load_torque"], {}, torque_steps=[(2.0, 0.4), (3.5, 0.9)], seed=32),
]

# The user-law logs (issue 85): each hides a law the monitor's library lacks, and comes with
# the law file a user would write for it. In manifest.toml as [[user_law_log]], apart from
# the library guard's [[log]]s.
# The pump's law as its user writes it: the torque t1 at a reference speed (150 rad/s,
# near the running speed) and the exponent n, k = t1 / 150^n.
PUMP_W_REF = 150.0
PUMP_EXPR = "t1 * (abs(w) / 150)^n * sign(w)"

USER_LAW_LOGS = [
    Log("kw2p2_pulse1", "kw2p2", "direct-on-line start driving a reciprocating compressor "
        "(a load torque pulsing once per revolution, t0 + a sin(theta_m + phi), theta_m "
        "the shaft's angle, 0 at the log's start), no viscous load, variac steps", 4.0,
        ["compressor"], {}, variac=variac(0.6),
        load_law={"kind": "pulse", "order": 1, "t0_share": 0.65, "a_share": 0.25,
                  "phi": 0.9},
        law=UserLaw("compressor1.toml", "compressor", "load_torque",
                    "a reciprocating compressor whose torque pulses once per revolution",
                    expr="t0 + a * sin(theta + phi)",
                    parameters={"t0": (5.0, 0.0, 40.0, "N m"),
                                "a": (2.0, 0.0, 20.0, "N m"),
                                "phi": (0.5, -3.1416, 3.1416, "rad")}),
        seed=41),
    Log("kw7p5_pulse2", "kw7p5", "direct-on-line start driving a two-cylinder compressor "
        "(a load torque pulsing twice per revolution, t0 + a sin(2 theta_m + phi)), no "
        "viscous load, variac steps", 4.0, ["compressor"], {}, variac=variac(0.6),
        load_law={"kind": "pulse", "order": 2, "t0_share": 0.6, "a_share": 0.3,
                  "phi": -1.2},
        law=UserLaw("compressor2.toml", "compressor", "load_torque",
                    "a compressor whose torque pulses twice per revolution",
                    expr="t0 + a * sin(2*theta + phi)",
                    parameters={"t0": (15.0, 0.0, 120.0, "N m"),
                                "a": (8.0, 0.0, 60.0, "N m"),
                                "phi": (-0.6, -3.1416, 3.1416, "rad")}),
        seed=42),
    Log("kw7p5_pump", "kw7p5", "direct-on-line start driving a pump (load torque k "
        "|w|^2.7 sign(w), no viscous load besides the machine's own), variac steps", 4.0,
        ["pump"], {}, variac=variac(0.6),
        load_law={"kind": "power", "k": 5.0e-5, "n": 2.7},
        law=UserLaw("pump.toml", "pump", "load_torque",
                    "a pump whose torque goes with a power of the speed",
                    expr=PUMP_EXPR,
                    parameters={"t1": (25.0, 0.0, 200.0, "N m"),
                                "n": (2.0, 1.5, 3.5, "1")}),
        seed=43),
    Log("kw2p2_foreign_sat", "kw2p2", "direct-on-line start, viscous load 80 %, variac "
        "steps (-15 %, +10 %); a saturating machine whose magnetising curve is not of the "
        "library's form (psi = psi_s tanh(L_u i_m / psi_s))", 4.0, ["no-load test"], {},
        variac=variac(0.6), bl_share=0.8, saturating=True, curve="tanh",
        noload_table="kw2p2_noload.csv",
        law=UserLaw("noload.toml", "no-load test", "magnetising_curve",
                    "the machine's magnetising curve as its no-load test measured it",
                    table="../kw2p2_noload.csv"),
        seed=44),
]

# The library's laws that share a term with a user-law log's true law (information for the
# tests; not an allowance): name -> why.
LIBRARY_OVERLAP = {
    "pulse": [["load_torque", "the pulsing law's mean t0 is a constant load torque"]],
    "power": [["windage", "the library's windage k w|w| is the same law with n = 2"]],
    "tanh": [["saturation", "the library's saturation law is another curve of the same "
              "effect (Lm0 / (1 + (psi/psi_sat)^n)), which cannot follow a tanh curve"]],
}

# The no-load table's supply voltages (shares of the rated line voltage), rated frequency.
NOLOAD_SCALES = [0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.1, 1.2]


# --------------------------------------------------------------------------- simulation
def thermal(m: Machine, lg: Log):
    """R_s(t), R_r(t) of the log: the file's cold values x the warm factor x the drift."""
    d = lg.drift

    def rise(t):
        return 0.0 if d is None else d["rise_k"] * (1 - math.exp(-t / d["tau_s"]))

    r_s0, r_r0 = m.pars().R_s * lg.rs_factor, m.pars().R_r

    def r_s(t):
        return r_s0 * (1 + ALPHA_CU * rise(t))

    def r_r(t):
        return r_r0 * (1 + ALPHA_CU * rise(t)) if d is not None and d["rotor"] else r_r0

    return r_s, r_r


def machine_of(m: Machine, lg: Log):
    par = m.pars(lg.sat)
    if lg.rs_factor == 1.0 and lg.drift is None:
        return model.InductionMachine(par)
    return HeatedMachine(par, *thermal(m, lg))


def load_law_of(m: Machine, lg: Log):
    """A user-law log's load torque T_L(t, w, theta) [N m] and its true parameters."""
    r, law = m.rated(), lg.load_law
    if law["kind"] == "pulse":
        t0, a, phi, k = law["t0_share"] * r.t, law["a_share"] * r.t, law["phi"], law["order"]
        return (lambda t, w, theta: t0 + a * np.sin(k * theta + phi),
                {"t0": t0, "a": a, "phi": phi})
    if law["kind"] == "power":
        k, n = law["k"], law["n"]
        # The user's law is written with the torque at a reference speed (`t1` at
        # PUMP_W_REF), whose parameters the log shows apart: k and n of k |w|^n trade
        # along a valley over the log's narrow range of running speed.
        return (lambda t, w, theta: k * np.abs(w) ** n * np.sign(w),
                {"t1": k * PUMP_W_REF ** n, "n": n})
    raise ValueError(law["kind"])


def mechanics_of(m: Machine, lg: Log):
    r = m.rated()
    if lg.load_law is not None:
        if lg.bl_share or lg.torque_steps or lg.fan_k or lg.fan_share or lg.coulomb_share:
            raise ValueError(f"{lg.name}: a load law takes the whole load")
        return ShaftWithAngle(m.j, m.b, load_law_of(m, lg)[0]), 0.0, None
    fan_k = lg.fan_k if lg.fan_k is not None else lg.fan_share * r.t / (m.w_s / m.n_p) ** 2
    coulomb = (lg.coulomb_share * r.t, lg.coulomb_w0) if lg.coulomb_share else None
    b_l = friction(m.b, lg.bl_share * r.t / r.w_m, fan_k, coulomb)
    tau_l = steps([(t, s * r.t) for t, s in lg.torque_steps], 0.0)
    return model.StiffMechanicalSystem(J=m.j, B_L=b_l, tau_L=tau_l), fan_k, coulomb


def supply_of(m: Machine, lg: Log):
    a = steps(lg.variac, 1.0)
    k, ang = lg.unbalance if lg.unbalance else (0.0, 0.0)
    neg = k * np.exp(1j * math.radians(ang))
    w = m.w_s

    def u_ss(t):
        return m.u_peak * a(t) * (np.exp(1j * w * t) + neg * np.exp(-1j * w * t))

    return u_ss


def integrate(mdl, y0, t_end, times, breaks):
    """Integrates motulator's `Model.rhs` from 0 to t_end segment by segment between the
    breaks (steps of the supply or the load); the states at `times`."""
    edges = [0.0] + sorted(b for b in breaks if 0 < b < t_end) + [t_end]
    y = np.asarray(y0, dtype=complex)
    out = []
    for a, b in zip(edges[:-1], edges[1:]):
        sel = times[(times >= a) & (times < b)]
        ev = np.append(sel, b)
        sol = solve_ivp(mdl.rhs, (a, b), y, method="DOP853", t_eval=ev, rtol=1e-9,
                        atol=1e-9)
        if sol.status != 0:
            raise RuntimeError(sol.message)
        out.append(sol.y[:, :-1])
        y = sol.y[:, -1]
    return np.concatenate(out, axis=1)


def currents(machine, psi_ss, psi_rs):
    """Stator current by motulator's own post-processing of the states."""
    machine.data = SimpleNamespace(psi_ss=psi_ss, psi_rs=psi_rs)
    machine.post_process_states()
    return machine.data.i_ss


def simulate_dol(m: Machine, lg: Log):
    machine = machine_of(m, lg)
    mech, _, _ = mechanics_of(m, lg)
    u_ss = supply_of(m, lg)
    mdl = DirectOnLine(IdealSupply(u_ss), machine, mech)
    n = int(round(lg.duration_s * lg.rate_hz))
    t = np.arange(n) / lg.rate_hz
    breaks = [p[0] for p in lg.variac] + [p[0] for p in lg.torque_steps]
    y = integrate(mdl, mdl.get_initial_values(), lg.duration_s, t, breaks)
    if lg.sat == "tanh":
        x = float(np.max(np.abs(y[0]))) / m.tanh_curve["psi_s"]
        if x >= TANH_X_MAX:
            raise RuntimeError(f"{lg.name}: the flux reached {x:.4f} psi_s")
    i_ss = currents(machine, y[0], y[1])
    return t, u_ss(t), i_ss, y[2].real


def simulate_vf(m: Machine, lg: Log):
    nom = NominalValues(U=m.v_ll, I=m.rated().i, f=m.f_hz, P=m.p_rated_w, tau=m.rated().t)
    base = BaseValues.from_nominal(nom, n_p=m.n_p)
    machine = machine_of(m, lg)
    mech, _, _ = mechanics_of(m, lg)
    conv = model.VoltageSourceConverter(u_dc=650.0)
    mdl = model.Drive(converter=conv, machine=machine, mechanics=mech)
    mdl.pwm = half_period_zoh
    T_s = 125e-6
    # The control's own model: the machine's nominal inverse-Gamma values.
    est = InductionMachineInvGammaPars(n_p=m.n_p, **m.inv_gamma())
    ctrl = control.VHzControl(control.VHzControlCfg(est, nom_psi_s=base.psi, T_s=T_s))
    tt, vv = zip(*lg.vf_profile)
    ctrl.ref.w_m = Sequence(np.array(tt), base.w * np.array(vv))
    sim = model.Simulation(mdl, ctrl)
    sim.simulate(t_stop=lg.duration_s + T_s)
    d = mdl.machine.data
    every = int(round(1 / (lg.rate_hz * T_s)))
    n = int(round(lg.duration_s * lg.rate_hz))
    mids = (np.arange(n) * every + 0.5) * T_s
    idx = np.searchsorted(d.t, mids - 1e-7)
    if np.max(np.abs(d.t[idx] - mids)) > 1e-7:
        raise RuntimeError("the middle of a hold is not a solver point")
    return (mids - 0.5 * T_s, d.u_ss[idx], d.i_ss[idx], mdl.mechanics.data.w_M[idx])


# --------------------------------------------------------------------------- sensors, files
def adc(x, full_scale, rng):
    """A 12-bit reading of +/- full_scale with Gaussian noise of one LSB; counts clipped."""
    lsb = full_scale / 2 ** (BITS - 1)
    code = np.round((x + rng.normal(0.0, lsb, x.shape)) / lsb)
    clipped = int(np.sum((code < -2 ** (BITS - 1)) | (code > 2 ** (BITS - 1) - 1)))
    code = np.clip(code, -2 ** (BITS - 1), 2 ** (BITS - 1) - 1)
    return code * lsb, lsb, clipped


def decimals(lsb):
    """Decimals that keep a reading within 5 % of an LSB."""
    return max(0, math.ceil(-math.log10(lsb / 20)))


def write_csv(path, t, u_ss, i_ss, w_m, m: Machine, seed):
    rng = np.random.default_rng(seed)
    v_fs, i_fs = m.ranges()
    v, v_lsb, v_clip = adc(complex2abc(u_ss), v_fs, rng)
    i, i_lsb, i_clip = adc(complex2abc(i_ss), i_fs, rng)
    if v_clip or i_clip:
        raise RuntimeError(f"{path.name}: {v_clip} voltage and {i_clip} current readings "
                           "clipped")
    w = np.round(w_m + rng.normal(0.0, 0.02, w_m.shape), 3)
    cols = np.column_stack([t, v.T, i.T, w])
    dv, di = decimals(v_lsb), decimals(i_lsb)
    fmt = ["%.4f"] + [f"%.{dv}f"] * 3 + [f"%.{di}f"] * 3 + ["%.3f"]
    np.savetxt(path, cols, fmt=fmt, delimiter=",", comments="",
               header="t_s,va_V,vb_V,vc_V,ia_A,ib_A,ic_A,wm_rad_s")
    return {"v_range_v": v_fs, "i_range_a": i_fs, "v_lsb_v": v_lsb, "i_lsb_a": i_lsb,
            "peak_current_a": float(np.max(np.abs(complex2abc(i_ss))))}


# --------------------------------------------------------------------------- the user's tests
def readings(t, u_ss, i_ss, w_m):
    """What a power analyser reads: per-phase RMS voltage and current, total power."""
    u, i = complex2abc(u_ss), complex2abc(i_ss)
    v_ph = float(np.sqrt(np.mean(u ** 2)))
    i_ph = float(np.sqrt(np.mean(i ** 2)))
    p = float(np.mean(np.sum(u * i, axis=0)))
    return {"v_ll_v": v_ph * math.sqrt(3), "v_ph_v": v_ph, "i_a": i_ph, "p_w": p,
            "speed_rad_s": float(np.mean(w_m))}


def run_test(m: Machine, sat, mechanics, v_scale, seconds):
    """A steady test: motulator's machine (saturation law `sat`, see `Machine.pars`) on a
    balanced supply at v_scale x rated for `seconds`; the readings over its last 20
    periods (200 points each)."""
    machine = model.InductionMachine(m.pars(sat))
    w, u = m.w_s, m.u_peak * v_scale

    def u_ss(t):
        return u * np.exp(1j * w * t)

    mdl = DirectOnLine(IdealSupply(u_ss), machine, mechanics)
    win = 20 / m.f_hz
    t = seconds - win + np.arange(4000) * win / 4000
    y = integrate(mdl, mdl.get_initial_values(), seconds, t, [seconds - win])
    w_m = y[2].real if y.shape[0] > 3 else np.zeros_like(t)
    return readings(t, u_ss(t), currents(machine, y[0], y[1]), w_m)


def no_load_test(m: Machine, sat, v_scale=1.0):
    mech = model.StiffMechanicalSystem(J=m.j, B_L=m.b)
    mech.state.w_M = m.w_s / m.n_p  # started and run up beforehand
    seconds = 4.0 if m.j < 1 else 12.0
    return run_test(m, sat, mech, v_scale, seconds)


def noload_table(m: Machine, sat, path):
    """A lab's no-load test table: the shaft free (the machine's own friction only), rated
    frequency, the supply at each of NOLOAD_SCALES x rated; the steady RMS line voltage and
    RMS phase current, rounded like a meter to 4 significant digits."""
    def meter(v):
        return f"{v:#.4g}".rstrip(".")

    rows = [no_load_test(m, sat, k) for k in NOLOAD_SCALES]
    lines = ["v_ll_rms_V,i0_rms_A"] + [f"{meter(r['v_ll_v'])},{meter(r['i_a'])}"
                                       for r in rows]
    path.write_text("\n".join(lines) + "\n")
    return rows


def locked_rotor_test(m: Machine, sat):
    """Rotor held, rated frequency, voltage lowered until the current is rated."""
    i_rated = m.rated().i
    v_scale = 0.25
    for _ in range(4):
        mech = model.ExternalRotorSpeed()
        r = run_test(m, sat, mech, v_scale, 3.0)
        v_scale *= i_rated / r["i_a"]
    r["v_scale"] = v_scale
    return r


def ieee112_file(m: Machine, sat):
    """The parameter file a user derives (module docstring): values and the readings."""
    lr = locked_rotor_test(m, sat)
    nl = no_load_test(m, sat)
    w = m.w_s
    rs = m.rs  # the DC test: cold, exact
    r_lr = lr["p_w"] / 3 / lr["i_a"] ** 2
    x_lr = math.sqrt((lr["v_ph_v"] / lr["i_a"]) ** 2 - r_lr ** 2)
    x1 = X1_SHARE[m.design] * x_lr
    x2 = x_lr - x1
    s_nl = 3 * nl["v_ph_v"] * nl["i_a"]
    x_nl = math.sqrt(s_nl ** 2 - nl["p_w"] ** 2) / 3 / nl["i_a"] ** 2
    xm = x_nl - x1
    p_rot = nl["p_w"] - 3 * nl["i_a"] ** 2 * rs
    b = max(p_rot, 0.0) / nl["speed_rad_s"] ** 2
    f = {"rs_ohm": rs, "rr_ohm": r_lr - rs, "ls_h": (xm + x1) / w, "lr_h": (xm + x2) / w,
         "lm_h": xm / w, "poles": m.poles, "j_kgm2": m.j * m.j_datasheet_factor,
         "b_nms": b, "bl_nms": 0.0}
    steps_ = {"r_lr_ohm": r_lr, "x_lr_ohm": x_lr, "x1_ohm": x1, "x2_ohm": x2,
              "x_nl_ohm": x_nl, "xm_ohm": xm, "p_rotational_w": p_rot}
    return f, {"locked_rotor": lr, "no_load": nl, "reduction": steps_}


def file_inv_gamma(f):
    lm, ls, lr = f["lm_h"], f["ls_h"], f["lr_h"]
    return {"R_s": f["rs_ohm"], "R_R": f["rr_ohm"] * (lm / lr) ** 2,
            "L_sgm": ls - lm ** 2 / lr, "L_M": lm ** 2 / lr}


def off_pct(value, truth):
    return None if truth == 0 else 100.0 * (value / truth - 1.0)


# The parameter file's name's suffix and its comment, per saturation law.
SAT_FILES = {None: ("", ""),
             "qu2012": ("_saturating", "a saturating machine (motulator's saturation law): "
                        "lm_h is the no-load test's rated-point value"),
             "tanh": ("_foreign_sat", "a saturating machine (a tanh magnetising curve, not "
                      "of the library's form): lm_h is the no-load test's rated-point value")}


def write_params(path, m: Machine, f, sat):
    what = SAT_FILES[sat][1]
    lines = [
        f"# {m.title}: the parameter file a user derives, not the simulator's values.",
        "# Made by tools/motulator-logs/generate.py: nameplate (voltage, frequency, poles),",
        "# the cold DC stator resistance, a locked-rotor test at rated current (rr_ohm and",
        f"# the leakages, split {X1_SHARE[m.design]:.0%} stator by NEMA design "
        f"{m.design}), a no-load test at rated",
        "# voltage (lm_h, and b_nms from the no-load loss balance), J from the datasheet;",
        "# bl_nms = 0 (the load is not known as a viscous coefficient).",
    ]
    if what:
        lines.append(f"# {what}.")
    lines += ["[motor]"]
    for k in ["rs_ohm", "rr_ohm", "ls_h", "lr_h", "lm_h", "poles", "j_kgm2", "b_nms",
              "bl_nms"]:
        v = f[k]
        lines.append(f"{k} = {v}" if k == "poles" else f"{k} = {v:.6g}")
    lines += ["", "[supply]", f"v_ll_rms = {m.v_ll:.1f}", f"f_hz = {m.f_hz:.1f}", ""]
    path.write_text("\n".join(lines))


# --------------------------------------------------------------------------- manifest
def toml_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if isinstance(v, (float, np.floating)):
        return repr(float(round(float(v), 10))) if math.isfinite(v) else '"nan"'
    if isinstance(v, str):
        return json.dumps(v, ensure_ascii=False)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    raise TypeError(type(v))


def toml_table(header, d):
    lines = [header] if header else []
    subs = []
    for k, v in d.items():
        if v is None:
            continue
        if isinstance(v, dict):
            subs.append((k, v))
        else:
            lines.append(f"{k} = {toml_value(v)}")
    out = "\n".join(lines) + "\n"
    base = header.strip("[]") if header else ""
    for k, v in subs:
        name = f"{base}.{k}" if base else k
        out += "\n" + toml_table(f"[{name}]", v)
    return out


def log_sizes(m: Machine, lg: Log, fan_k, coulomb):
    """The hidden effects' (and the loads') true sizes for the manifest."""
    r = m.rated()
    s = {"rated_torque_nm": r.t, "rated_speed_rad_s": r.w_m, "rated_current_a": r.i}
    if lg.bl_share:
        s["viscous_load_nms"] = lg.bl_share * r.t / r.w_m
    if fan_k:
        s["windage_k_nms2"] = fan_k
    if coulomb:
        s["coulomb_torque_nm"], s["coulomb_omega0_rad_s"] = coulomb
    if lg.torque_steps:
        s["load_torque_steps"] = [[t, x * r.t] for t, x in lg.torque_steps]
    if lg.variac:
        s["supply_voltage_steps"] = [list(p) for p in lg.variac]
    if lg.unbalance:
        s["supply_unbalance_fraction"], s["supply_unbalance_angle_deg"] = lg.unbalance
    if lg.rs_factor != 1.0:
        s["stator_resistance_factor"] = lg.rs_factor
        s["stator_resistance_ohm"] = m.rs * lg.rs_factor
    if lg.drift:
        d = lg.drift
        s["drift_rise_k"], s["drift_tau_s"] = d["rise_k"], d["tau_s"]
        s["drift_alpha_per_k"] = ALPHA_CU
        s["drift_windings"] = "stator and rotor" if d["rotor"] else "stator only"
        end = d["rise_k"] * (1 - math.exp(-lg.duration_s / d["tau_s"]))
        s["drift_rise_at_end_k"] = end
        s["drift_resistance_at_end"] = 1 + ALPHA_CU * end
    if lg.sat == "qu2012":
        sat = m.saturation
        s["saturation_law"] = ("motulator Gamma model: L_s(psi_s) = L_su / (1 + "
                               "(|psi_s|/psi_k)^S)")
        s["saturation_L_su_h"], s["saturation_psi_k_wb"] = sat["L_su"], sat["psi_k"]
        s["saturation_S"] = sat["S"]
        s["saturation_L_s_at_rated_flux_h"] = m.pars("qu2012").L_s(m.u_peak / m.w_s)
    if lg.sat == "tanh":
        c = m.tanh_curve
        s["saturation_law"] = ("motulator Gamma model, a tanh magnetising curve: psi_s = "
                               "psi_sat tanh(L_u i_m / psi_sat), i.e. L_s(psi) = psi / i_m, "
                               "i_m = (psi_sat / L_u) atanh(psi / psi_sat)")
        s["saturation_psi_sat_wb"], s["saturation_L_u_h"] = c["psi_s"], c["L_u"]
        psi_r = m.u_peak / m.w_s
        s["saturation_rated_flux_wb"] = psi_r
        s["saturation_L_s_at_rated_flux_h"] = m.pars("tanh").L_s(psi_r)
        s["saturation_L_s_ratio_at_rated_flux"] = m.pars("tanh").L_s(psi_r) / c["L_u"]
    if lg.load_law is not None:
        law, true = lg.load_law, load_law_of(m, lg)[1]
        if law["kind"] == "pulse":
            s["load_law"] = f"T_L = t0 + a sin({law['order']} theta_m + phi)"
            s["load_t0_nm"], s["load_a_nm"], s["load_phi_rad"] = (
                true["t0"], true["a"], true["phi"])
            s["load_pulses_per_revolution"] = law["order"]
        else:
            k = law["k"]
            s["load_law"] = "T_L = k |w_m|^n sign(w_m) = t1 (|w_m| / 150 rad/s)^n sign(w_m)"
            s["load_k"], s["load_n"], s["load_t1_nm"] = k, true["n"], true["t1"]
            s["load_k_unit"] = "N m (s/rad)^n"
            s["load_torque_at_synchronous_speed_nm"] = k * (m.w_s / m.n_p) ** true["n"]
    if lg.drive == "vf":
        s["vf_speed_reference_pu"] = [list(p) for p in lg.vf_profile]
        s["vf_control"] = ("motulator VHzControl (k_u 1, k_w 4), T_s 125 us, average "
                           "converter, 650 V DC bus, the control's model the machine's "
                           "nominal values")
    return s


def sat_order(key):
    """Parameter files in the order machine, linear before saturating."""
    return key[0], key[1] is not None, key[1] or ""


def shaft_frequencies(t, w, lg: Log, order):
    """The true shaft frequency [Hz] of each steady stretch (between the supply's steps;
    the mean noise-free speed over the stretch's last 0.3 s, about 7 revolutions) and the
    amplitude of the speed's line at `order` x the shaft frequency there (its projection
    on exp(-j order theta_m), theta_m integrated from the speed)."""
    theta = np.concatenate([[0.0], np.cumsum(0.5 * (w[1:] + w[:-1]) * np.diff(t))])
    edges = [0.0] + [p[0] for p in lg.variac] + [lg.duration_s]
    out = []
    for a, b in zip(edges[:-1], edges[1:]):
        sel = (t >= b - 0.3) & (t < b)
        f = float(np.mean(w[sel])) / math.tau
        dw = w[sel] - np.mean(w[sel])
        ripple = 2 * abs(np.mean(dw * np.exp(-1j * order * theta[sel])))
        out.append([a, b, f, order * f, float(ripple)])
    return out


def check_starts(lg: Log, truth: dict):
    """The user's starts are guesses, 25-60 % off the truth (the pump's exponent starts at
    2, a fan's, 26 % below its 2.7), and the bounds hold the truth."""
    for k, (start, low, high, _) in lg.law.parameters.items():
        off = abs(start / truth[k] - 1)
        if not (0.25 <= off <= 0.6 and low < truth[k] < high):
            raise ValueError(f"{lg.law.file}: {k} start {start} is {off:.0%} off the truth "
                             f"{truth[k]:.6g} or its bounds [{low}, {high}] miss it")


def write_law_file(path, lg: Log):
    """The user's law file, in issue 85's form."""
    law = lg.law
    lines = [f"# The user's law for {lg.name}.csv: {law.comment}.",
             "# What a user writes knowing the physics but not the numbers: the starts are",
             "# guesses, the bounds physical and generous. Made by tools/motulator-logs/",
             "# generate.py; the true law and its values are in ../manifest.toml",
             f"# ([[user_law_log]] {lg.name}).",
             "[[law]]",
             f"name = {toml_value(law.name)}",
             f"acts_on = {toml_value(law.acts_on)}"]
    if law.expr is not None:
        lines.append(f"expr = {toml_value(law.expr)}")
    if law.table is not None:
        lines.append(f"table = {toml_value(law.table)}")
    if law.parameters:
        lines.append("[law.parameters]")
        for k, (start, low, high, unit) in law.parameters.items():
            lines.append(f"{k} = {{ start = {start!r}, low = {low!r}, high = {high!r}, "
                         f"unit = {toml_value(unit)} }}")
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(lines) + "\n")


def user_law_entry(m: Machine, lg: Log, out, t, w, made_table):
    """What a [[user_law_log]] adds to a [[log]]: the law file, the true law, the library's
    laws that share a term with it, the shaft's frequencies, the no-load table."""
    law = lg.law
    e = {"laws": f"laws/{law.file}", "law_name": law.name, "law_acts_on": law.acts_on}
    if lg.load_law is not None:
        kind, true = lg.load_law["kind"], load_law_of(m, lg)[1]
        if kind == "pulse":
            k = lg.load_law["order"]
            expr = f"t0 + a * sin({k}*theta + phi)" if k != 1 else "t0 + a * sin(theta + phi)"
        else:
            k, expr = 1, PUMP_EXPR
        e["true_law"] = {"acts_on": "load_torque", "expr": expr,
                         "note": "theta the shaft's mechanical angle (rad, 0 at t = 0, "
                                 "integrated from the speed), w the mechanical speed (rad/s)",
                         "parameters": true}
        e["library_overlap"] = LIBRARY_OVERLAP[kind]
        fr = shaft_frequencies(t, w, lg, k)
        e["frequencies"] = {
            "note": ("per steady stretch [t_from_s, t_to_s, value]; the shaft frequency is "
                     "the mean speed over the stretch's last 0.3 s over 2 pi"),
            "pulses_per_revolution": k if kind == "pulse" else 0,
            "shaft_hz": [[a, b, f] for a, b, f, _, _ in fr],
            "supply_hz": m.f_hz,
        }
        if kind == "pulse":
            e["frequencies"]["pulsation_hz"] = [[a, b, p] for a, b, _, p, _ in fr]
            e["frequencies"]["speed_ripple_at_pulsation_rad_s"] = [
                [a, b, r] for a, b, _, _, r in fr]
    if lg.sat == "tanh":
        c = m.tanh_curve
        e["true_law"] = {"acts_on": "magnetising_curve",
                         "expr": "psi = psi_sat * tanh(L_u * i_m / psi_sat)",
                         "note": ("motulator's Gamma model: psi the stator flux (Wb, "
                                  "peak), i_m the magnetising current (A, peak), "
                                  "L_s(psi) = psi / i_m(psi)"),
                         "parameters": {"psi_sat_wb": c["psi_s"], "L_u_h": c["L_u"]}}
        e["library_overlap"] = LIBRARY_OVERLAP["tanh"]
    if lg.noload_table is not None:
        data = (out / lg.noload_table).read_bytes()
        e["noload_table"] = {
            "csv": lg.noload_table, "bytes": len(data),
            "sha256": hashlib.sha256(data).hexdigest(),
            "test": ("the machine of this log at no load (shaft free, its own friction "
                     "b only), rated frequency, each voltage held 4 s from synchronous "
                     "speed; RMS line voltage and RMS phase current over the last 20 "
                     "periods, rounded to 4 significant digits"),
            "v_scale": NOLOAD_SCALES,
            "v_ll_rms_v": [r["v_ll_v"] for r in made_table],
            "i0_rms_a": [r["i_a"] for r in made_table],
            "i0_reactive_rms_a": [math.sqrt(max(r["i_a"] ** 2 - (r["p_w"] / 3 / r["v_ph_v"])
                                                ** 2, 0.0)) for r in made_table],
            "note": ("i0 holds the in-phase current of the no-load losses (the friction's "
                     "b w^2 and the copper's): a large share at the lowest voltages, where "
                     "the slip grows; i0_reactive_rms_a is its part in quadrature (from "
                     "the power p_w, which the table does not give)"),
            "p_w": [r["p_w"] for r in made_table],
            "speed_rad_s": [r["speed_rad_s"] for r in made_table],
        }
    return e


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", type=pathlib.Path, default=OUT)
    ap.add_argument("--only", nargs="*", help="log names to make (default: all)")
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    t_all = time.time()
    known = {lg.name for lg in LOGS + USER_LAW_LOGS}
    for name in args.only or []:
        if name not in known:
            raise SystemExit(f"no log named {name!r} (known: {', '.join(sorted(known))})")

    # The users' parameter files: one per machine (and per saturating variant); the
    # library guard's first, then those only the user-law logs need.
    files, unchanged = {}, set()
    keys = sorted({(lg.machine, lg.sat) for lg in LOGS}, key=sat_order)
    keys += sorted({(lg.machine, lg.sat) for lg in USER_LAW_LOGS} - set(keys), key=sat_order)
    for key in keys:
        m = MACHINES[key[0]]
        f, tests = ieee112_file(m, key[1])
        name = f"{m.name}{SAT_FILES[key[1]][0]}.toml"
        before = (args.out / name).read_bytes() if (args.out / name).exists() else None
        write_params(args.out / name, m, f, key[1])
        if (args.out / name).read_bytes() == before:
            unchanged.add(name)
        files[key] = (name, f, tests)
        print(f"{name}: " + ", ".join(f"{k} {v:.4g}" for k, v in f.items()))

    manifest = [
        "# The third-party guard's logs (sim-host/tests/cli/ladder_third_party.rs): made by",
        f"# tools/motulator-logs/generate.py with motulator {MOTULATOR}, numpy "
        f"{np.__version__}.",
        "# Regenerate them with the generator, never by hand.",
        "# Per log: the hidden effects (what the ladder must name; `warm_stator` is a base",
        "# change of rs of size `warm_stator`), the effects the log's physics allows besides",
        "# them, effects that are the same term on this log (`equivalent`: hidden, named,",
        "# why), and the true sizes. Per machine: the truth, the user's file and the tests",
        "# it came from.",
        "# [[user_law_log]] (issue 85): logs whose hidden law the library lacks, each with",
        "# the user's law file (`laws`, its `law_name` is what `hidden` holds), the true law",
        "# and its values (`true_law`), the library's laws sharing a term with it",
        "# (`library_overlap`, not an allowance) and the shaft's true frequencies.",
        "",
        toml_table("", {"motulator": MOTULATOR, "numpy": np.__version__,
                        "generator": "tools/motulator-logs/generate.py"}),
    ]
    # A run with --only keeps the manifest's entry of a machine whose file came out the
    # same: the tests' readings differ in their last digits from one CPU to another
    # (numpy's SIMD sums), and the entries of the logs not made must not move.
    old_path = args.out / "manifest.toml"
    old = tomllib.loads(old_path.read_text()) if old_path.exists() else {}
    old_machines = {e["params"]: e for e in old.get("machine", [])}
    for (mname, sat), (pname, f, tests) in files.items():
        if args.only and pname in unchanged and pname in old_machines:
            manifest.append(toml_table("[[machine]]", old_machines[pname]))
            continue
        m = MACHINES[mname]
        r = m.rated()
        ig_t, ig_f = m.inv_gamma(), file_inv_gamma(f)
        truth = m.truth_table()
        entry = {
            "name": mname, "saturating": sat is not None, "params": pname,
            "saturation_curve": (None if sat != "tanh" else
                                 "in place of the source's law, a tanh magnetising curve "
                                 f"psi = psi_sat tanh(L_u i_m / psi_sat), psi_sat "
                                 f"{m.tanh_curve['psi_s']} Wb, L_u {m.tanh_curve['L_u']} H "
                                 "(Gamma model)"),
            "title": m.title,
            "source": m.source,
            "nameplate": {"v_ll_rms": m.v_ll, "f_hz": m.f_hz, "poles": m.poles,
                          "p_w": m.p_rated_w, "i_a": r.i, "speed_rpm": r.w_m * 60 / math.tau,
                          "torque_nm": r.t, "nema_design": m.design},
            "truth": truth,
            "truth_inverse_gamma": ig_t,
            "file": f,
            "file_off_pct": {k: off_pct(f[k], truth[k]) for k in
                             ["rs_ohm", "rr_ohm", "ls_h", "lr_h", "lm_h", "j_kgm2", "b_nms"]},
            "file_inverse_gamma_off_pct": {k: off_pct(ig_f[k], ig_t[k]) for k in ig_t},
            "tests": tests,
        }
        manifest.append(toml_table("[[machine]]", entry))

    # A log not made in this run keeps the entry the manifest on disk holds (a run with
    # --only rewrites the manifest only when it knows every log's entry).
    old_entries = {(arr, e["name"]): e for arr in ("log", "user_law_log")
                   for e in old.get(arr, [])}
    complete = True
    for arr, lg in [("log", x) for x in LOGS] + [("user_law_log", x) for x in USER_LAW_LOGS]:
        if args.only and lg.name not in args.only:
            if (arr, lg.name) in old_entries:
                manifest.append(toml_table(f"[[{arr}]]", old_entries[(arr, lg.name)]))
            else:
                complete = False
            continue
        m = MACHINES[lg.machine]
        if lg.load_law is not None:
            check_starts(lg, load_law_of(m, lg)[1])
        t0 = time.time()
        t, u, i, w = (simulate_vf if lg.drive == "vf" else simulate_dol)(m, lg)
        csv = args.out / f"{lg.name}.csv"
        sensors = write_csv(csv, t, u, i, w, m, lg.seed)
        _, fan_k, coulomb = mechanics_of(m, lg)
        pname = files[(lg.machine, lg.sat)][0]
        data = csv.read_bytes()
        entry = {
            "name": lg.name, "csv": csv.name, "params": pname, "machine": lg.machine,
            "scenario": lg.scenario, "drive": lg.drive, "rate_hz": lg.rate_hz,
            "duration_s": lg.duration_s, "rows": len(t), "bytes": len(data),
            "sha256": hashlib.sha256(data).hexdigest(),
            "hidden": lg.hidden,
            "allowed": DYNAMICS + lg.allowed,
            "equivalent": [list(e) for e in lg.equivalent],
            "stator_at_file_temperature": lg.rs_factor == 1.0 and lg.drift is None,
            "warm_stator": lg.rs_factor - 1.0 if lg.rs_factor != 1.0 else None,
        }
        if lg.law is not None:
            table = (noload_table(m, lg.sat, args.out / lg.noload_table)
                     if lg.noload_table else None)
            write_law_file(args.out / "laws" / lg.law.file, lg)
            entry.update(user_law_entry(m, lg, args.out, t, w, table))
        entry["sizes"] = log_sizes(m, lg, fan_k, coulomb)
        entry["sensors"] = sensors
        manifest.append(toml_table(f"[[{arr}]]", entry))
        print(f"{lg.name}: {len(t)} rows, {len(data) / 1e6:.2f} MB, peak current "
              f"{sensors['peak_current_a']:.1f} A of {sensors['i_range_a']} A, "
              f"{time.time() - t0:.1f} s")
    if complete:
        old_path.write_text("\n".join(manifest))
    else:
        print(f"{old_path} not written: it does not hold every log not made in this run")
    print(f"done in {time.time() - t_all:.0f} s")


if __name__ == "__main__":
    main()
