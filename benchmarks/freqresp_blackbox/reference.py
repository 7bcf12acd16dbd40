"""Independent reference for the freqresp black-box check (numpy/scipy only).

Written by a black-box tester who had not read synth's code: transfer functions with their exact
response and continuous phase, handling-quality metrics, log chirps and ``lsim`` simulation.
"""

import numpy as np
import scipy.signal as sg
from scipy.optimize import brentq


class Plant:
    """H(s) = k * prod(s+z) / (s^nint * prod(s+p) * prod(s^2+a s+b)) * exp(-Td s)"""

    def __init__(self, k, zeros=(), poles=(), quads=(), nint=0, Td=0.0):
        self.k = k
        self.zeros = list(zeros)
        self.poles = list(poles)
        self.quads = list(quads)
        self.nint = nint
        self.Td = Td
        num = np.array([k])
        for z in self.zeros:
            num = np.polymul(num, [1, z])
        den = np.array([1.0])
        for p in self.poles:
            den = np.polymul(den, [1, p])
        for a, b in self.quads:
            den = np.polymul(den, [1, a, b])
        for _ in range(nint):
            den = np.polymul(den, [1, 0])
        self.num = num
        self.den = den

    def H(self, w):
        """Exact complex response at the frequencies w (rad/s)."""
        s = 1j * np.asarray(w, float)
        return np.polyval(self.num, s) / np.polyval(self.den, s) * np.exp(-s * self.Td)

    def mag_db(self, w):
        """Exact magnitude in dB."""
        return 20 * np.log10(np.abs(self.H(w)))

    def phase_deg(self, w):
        """Continuous phase in degrees: sum of factor phases (exact, no unwrapping needed)."""
        w = np.asarray(w, float)
        ph = np.zeros_like(w) + (0.0 if self.k > 0 else -180.0)
        for z in self.zeros:
            ph += np.degrees(np.arctan2(w, z))  # (jw+z); z<0 -> RHP zero
        for p in self.poles:
            ph -= np.degrees(np.arctan2(w, p))
        for a, b in self.quads:
            ph -= np.degrees(np.arctan2(a * w, b - w**2))
        ph -= 90 * self.nint
        ph -= np.degrees(w * self.Td)
        return ph

    def formula(self, d=10):
        """The transfer function as a synth formula string (without the delay)."""

        def f(x):
            return f"{x:.{d}g}"

        num = f(self.k) + "".join(f"*(s+{f(z)})" if z >= 0 else f"*(s-{f(-z)})" for z in self.zeros)
        dens = ["s"] * self.nint + [f"(s+{f(p)})" for p in self.poles] + [f"(s^2+{f(a)}*s+{f(b)})" for a, b in self.quads]
        den = "*".join(dens) if dens else "1"
        return f"{num}/({den})"

    def lti(self):
        """The delay-free part as a scipy.signal.lti."""
        return sg.lti(self.num, self.den)


def _cross(fun, level, w, down=True):
    v = fun(w) - level
    idx = np.where((v[:-1] > 0) & (v[1:] <= 0))[0] if down else np.where((v[:-1] < 0) & (v[1:] >= 0))[0]
    out = []

    def g(lw):
        return fun(np.array([np.exp(lw)]))[0] - level

    for i in idx:
        out.append(float(np.exp(brentq(g, np.log(w[i]), np.log(w[i + 1]), xtol=1e-12))))
    return out


def hq_metrics(pl, rtype="auto", wlo=1e-4, whi=1e4, n=400001):
    """Handling-quality metrics (w180, -135 deg and +6 dB bandwidths, phase delay) from the exact response."""
    w = np.logspace(np.log10(wlo), np.log10(whi), n)
    ph = pl.phase_deg
    c180 = _cross(ph, -180, w)
    c135 = _cross(ph, -135, w)
    r = {"w180": c180[0] if c180 else None, "bandwidth_phase": c135[0] if c135 else None}
    if rtype == "auto":
        rtype = "rate" if pl.nint > 0 else "attitude"
    r["type"] = rtype
    if r["w180"] is None:
        return r
    w180 = r["w180"]
    g180 = pl.mag_db([w180])[0]
    wg = w[w < w180]
    cg = _cross(pl.mag_db, g180 + 6, np.append(wg, w180))
    r["bandwidth_gain"] = max(cg) if cg else None
    r["gain_w180_db"] = g180
    p2 = ph([2 * w180])[0]
    r["phase_2w180_deg"] = p2
    r["phase_delay"] = -(p2 + 180) / (57.3 * 2 * w180)
    r["phase_delay_exact"] = -np.radians(p2 + 180) / (2 * w180)
    if rtype == "rate":
        cands = [x for x in (r["bandwidth_phase"], r["bandwidth_gain"]) if x is not None]
        r["bandwidth"] = min(cands) if cands else None
    else:
        r["bandwidth"] = r["bandwidth_phase"]
    return r


def log_chirp(t, w0, w1, T, A=1.0, fade=0.0, t0=0.0):
    """Exponential sine sweep from w0 to w1 over T seconds starting at t0; zero outside."""
    tt = np.asarray(t) - t0
    f = np.log(w1 / w0)
    u = A * np.sin(w0 * T / f * (np.exp(f * np.clip(tt, 0, T) / T) - 1))
    if fade > 0:
        env = np.ones_like(tt)
        m = tt < fade
        env[m] = 0.5 - 0.5 * np.cos(np.pi * np.clip(tt[m], 0, None) / fade)
        m = tt > T - fade
        env[m] = 0.5 - 0.5 * np.cos(np.pi * np.clip(T - tt[m], 0, None) / fade)
        u = u * env
    u[(tt < 0) | (tt > T)] = 0
    return u


def simulate(pl, t, u, ufun=None):
    """y = H u. Delay: if ufun is given, evaluate u(t-Td) exactly; else interpolate."""
    if pl.Td > 0:
        if ufun is not None:
            ud = ufun(t - pl.Td)
        else:
            ud = np.interp(t - pl.Td, t, u, left=0.0)
    else:
        ud = u
    _, y, _ = sg.lsim(pl.lti(), ud, t)
    return y
