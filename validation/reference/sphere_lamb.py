#!/usr/bin/python3
"""Analytic natural frequencies of the free homogeneous elastic sphere (Lamb 1882) for
sphere.stp (shared models), steel: the reference of the free-free `sphere` model of
validation/order2_comparison.py.

  /usr/bin/python3 validation/reference/sphere_lamb.py [--step STEP] [--hexfem BIN]
      [--out validation/reference/sphere.json] [--check-sizes 2,1.4142136,1] [--workdir DIR]

Source: H. Lamb, "On the vibrations of an elastic sphere", Proc. London Math. Soc. 13 (1882)
189-212; the same two classes in Eringen & Suhubi, Elastodynamics vol. II (1975) section 8.13,
and Achenbach, Wave Propagation in Elastic Solids (1973). The form used here is derived below
from the potentials, with x = omega R / c_s and y = omega R / c_p = x c_s / c_p
(c_s^2 = mu / rho, c_p^2 = (lambda + 2 mu) / rho), in units R = 1, mu = 1, so
lambda + 2 mu = g2 = (c_p / c_s)^2 = 2 (1 - nu) / (1 - 2 nu) and lambda = g2 - 2.
The displacement is u = U(r) Y_n e_r + V(r) grad_1 Y_n (grad_1: surface gradient on the unit
sphere), whose tractions on a sphere r are
    sigma_rr = (lambda + 2 mu) U' + lambda (2 U - n (n + 1) V) / r       (times Y_n)
    sigma_rt = mu (V' - V / r + U / r)                                    (times grad_1 Y_n)
and the modes regular at r = 0 come from three potentials (j_n spherical Bessel of the first kind):
  * torsional (class I), u = curl(r j_n(k r) Y_n), purely tangential: the free surface needs
    d/dr (j_n(k r) / r) = 0 at r = R, i.e.
        T_n(x) = x j_n'(x) - j_n(x) = (n - 1) j_n(x) - x j_{n+1}(x) = 0.
    Independent of nu. n = 1 has the root x = 0 (rigid rotation), dropped; its roots x > 0 are
    elastic. n = 0 does not exist (curl(r Y_0) = 0).
  * spheroidal (class II), u = A grad(j_n(h r) Y_n) + B curl curl(r j_n(k r) Y_n), h = omega / c_p,
    k = omega / c_s:
        dilatational part: U = h j_n'(h r),              V = j_n(h r) / r
        shear part:        U = n (n + 1) j_n(k r) / r,   V = j_n(k r) / r + k j_n'(k r)
    (the shear part's radial component uses j_n'' + 2 j_n' / z = (n (n + 1) / z^2 - 1) j_n).
    Free surface: det [[sigma_rr(P), sigma_rr(S)], [sigma_rt(P), sigma_rt(S)]] = 0 at r = R = 1,
    evaluated exactly with j_n'' from Bessel's equation. n = 0 (breathing) has no shear part and
    reduces to sigma_rr(P) = 0, i.e. Lamb's eq. (59): tan y (4 - g2 y^2) = 4 y. n = 1 has the
    root x = 0 (rigid translation), dropped; its roots x > 0 are elastic.
Each root is a mode of multiplicity 2 n + 1 (the 2 n + 1 spherical harmonics of degree n).
f = x c_s / (2 pi R).

Roots: sign changes of each function on a grid of step 0.002 in x from 0.05 (below any
elastic root of a sphere: the lowest is 2.50) to the bound, each refined by brentq to
xtol 1e-13; the count is checked on a grid four times finer (a pair of roots closer than a step
would show up there). The spheroidal determinant is also checked against an independently
written closed form, Sato & Usami (1962), Geophys. Mag. 31, eq. 2.2 (in cylindrical Bessel
functions of half-integer order; its n = 0 row replaced by Lamb's eq. 59), root by root
(modes[].sato_usami_rel_diff), the torsional one against x j_n' - j_n with scipy's derivative
(modes[].derivative_form_rel_diff).

Checks written to the JSON:
  * published: Lamb (1882) p. 211 gives ka/pi = .842 for the gravest spheroidal mode of the second
    order (k = omega / c_s, a = radius) and uses it for a steel ball;
  * CalculiX: the chain of reference_chain.py, free-free (Gmsh P2 tets, C3D10, no *BOUNDARY, six
    rigid modes dropped), at --check-sizes, plus its Richardson extrapolation.
R comes from `hexfem info STEP` (half the bounding box; the CAD volume must match 4/3 pi R^3).
"""
import argparse
import json
import math
import os
import re
import subprocess
import sys

import numpy as np
from scipy.optimize import brentq
from scipy.special import jv, spherical_jn

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
import reference_chain as chain  # noqa: E402  (same material constants as the chain)

STEP = "/work/shared/models/sphere.stp"
NREF = 10  # reference_hz: the first 10 elastic frequencies, with multiplicity
XTOL = 1e-13


def jn(n, z, d=0):
    """j_n(z) (d = 0), j_n'(z) (d = 1) or j_n''(z) (d = 2, from Bessel's equation)."""
    if d == 0:
        return spherical_jn(n, z)
    if d == 1:
        return spherical_jn(n, z, derivative=True)
    return -2.0 / z * spherical_jn(n, z, derivative=True) - (1.0 - n * (n + 1) / z**2) * spherical_jn(n, z)


def moduli(nu):
    """(lambda + 2 mu, lambda) with mu = 1; c_p / c_s = sqrt(lambda + 2 mu)."""
    g2 = 2.0 * (1.0 - nu) / (1.0 - 2.0 * nu)
    return g2, g2 - 2.0


def torsional(n, x):
    return (n - 1) * jn(n, x) - x * jn(n + 1, x)


def spheroidal(n, x, nu):
    """The free-surface determinant of the spheroidal class at x = omega R / c_s (R = 1, mu = 1)."""
    g2, lam = moduli(nu)
    k, h = x, x / math.sqrt(g2)
    L = n * (n + 1)

    def tractions(U, dU, V, dV):
        return g2 * dU + lam * (2.0 * U - L * V), dV - V + U  # at r = 1

    # dilatational potential j_n(h r) Y_n: U = h j_n'(h r), V = j_n(h r) / r
    P = tractions(h * jn(n, h, 1), h * h * jn(n, h, 2), jn(n, h), h * jn(n, h, 1) - jn(n, h))
    if n == 0:
        return P[0]  # no shear part; sigma_rt vanishes identically
    # shear potential: U = L j_n(k r) / r, V = j_n(k r) / r + k j_n'(k r)
    U = L * jn(n, k)
    dU = L * (k * jn(n, k, 1) - jn(n, k))
    V = jn(n, k) + k * jn(n, k, 1)
    dV = (k * jn(n, k, 1) - jn(n, k)) + k * k * jn(n, k, 2)
    S = tractions(U, dU, V, dV)
    return P[0] * S[1] - P[1] * S[0]


def sato_usami(n, x, nu):
    """The same frequency equation as written by Sato & Usami (1962, eq. 2.2): a 2x2 determinant
    in J_{n+1/2}, J_{n+3/2} of X = omega R / c_p and x = omega R / c_s; n = 0 by Lamb's eq. (59)."""
    g2, _ = moduli(nu)
    X = x / math.sqrt(g2)
    if n == 0:
        return math.tan(X) * (4.0 - g2 * X * X) - 4.0 * X
    a = (0.5 - n * (n - 1) / x**2) * jv(n + 0.5, X) - 2.0 * X / x**2 * jv(n + 1.5, X)
    b = -2.0 * n * (n + 1) * ((n - 1) / x**2 * jv(n + 0.5, X) - X / x**2 * jv(n + 1.5, X))
    c = (n - 1) / x**2 * jv(n + 0.5, x) - jv(n + 1.5, x) / x
    d = 2.0 / x * jv(n + 1.5, x) + (2.0 * (n * n - 1) / x**2 - 1.0) * jv(n + 0.5, x)
    return a * d - b * c


def roots(f, xmax, step=0.002, x0=0.05):
    """Roots of f in (x0, xmax]: sign changes on a grid, refined by brentq."""
    xs = np.arange(x0, xmax + step, step)
    vs = np.array([f(x) for x in xs])
    out = []
    for i in range(len(xs) - 1):
        if vs[i] == 0.0:
            out.append(float(xs[i]))
        elif vs[i] * vs[i + 1] < 0.0:
            out.append(brentq(f, xs[i], xs[i + 1], xtol=XTOL, rtol=4 * np.finfo(float).eps))
    return out


def sign_changes(f, xmax, step, x0=0.05):
    """How many sign changes f has on a grid (tan-based functions jump at poles: only used on
    the regular determinants)."""
    vs = np.array([f(x) for x in np.arange(x0, xmax + step, step)])
    return int(np.sum(vs[:-1] * vs[1:] < 0))


def lamb_modes(nu, xmax, nmax=None):
    """Every mode with x = omega R / c_s <= xmax: dicts kind, n, overtone, x, multiplicity."""
    # the lowest root of degree n grows about like n (surface waves): n up to ~xmax suffices,
    # with margin; a degree with no root below xmax ends the search for its class
    nmax = nmax or int(xmax) + 3
    modes = []
    for kind, f0, n0 in (("torsional", lambda n: (lambda x: torsional(n, x)), 1),
                         ("spheroidal", lambda n: (lambda x: spheroidal(n, x, nu)), 0)):
        for n in range(n0, nmax + 1):
            f = f0(n)
            xs = roots(f, xmax)
            fine = sign_changes(f, xmax, 0.0005)
            if fine != len(xs):
                raise RuntimeError("%s n = %d: %d roots on the 0.002 grid, %d sign changes on "
                                   "the 0.0005 grid" % (kind, n, len(xs), fine))
            for i, x in enumerate(xs):
                # the bracket of width 2 XTOL x must still hold a sign change
                lo, hi = x * (1 - 10 * XTOL), x * (1 + 10 * XTOL)
                if f(lo) * f(hi) > 0:
                    raise RuntimeError("%s n = %d: root %.15g not bracketed" % (kind, n, x))
                modes.append({"kind": kind, "n": n, "overtone": i, "x": x,
                              "multiplicity": 2 * n + 1})
    return sorted(modes, key=lambda m: m["x"])


def radius_from_step(hexfem, step):
    """R and the CAD figures from `hexfem info`: half the bounding box, checked against the volume."""
    text = subprocess.run([hexfem, "info", step], check=True, stdout=subprocess.PIPE,
                          text=True).stdout
    vol = float(re.search(r"^volume ([0-9.eE+-]+) mm\^3", text, re.M).group(1))
    box = re.search(r"^bbox \[([^\]]+)\] - \[([^\]]+)\]", text, re.M)
    lo = np.array([float(v) for v in box.group(1).split()])
    hi = np.array([float(v) for v in box.group(2).split()])
    half = (hi - lo) / 2
    R = float(half.mean())
    if np.ptp(half) > 1e-6 * R or abs(vol / (4 / 3 * math.pi * R**3) - 1) > 1e-4:
        raise RuntimeError("%s is not a sphere: half extents %s, volume %g against 4/3 pi R^3 = %g"
                           % (step, half, vol, 4 / 3 * math.pi * R**3))
    return R, {"hexfem_info_volume_mm3": vol, "bbox_min": lo.tolist(), "bbox_max": hi.tolist(),
               "center": ((lo + hi) / 2).tolist()}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--step", default=STEP)
    ap.add_argument("--hexfem", default=os.environ.get("HEXFEM", "/tmp/hexfem-bin/hexfem"))
    ap.add_argument("--out", default=os.path.join(HERE, "sphere.json"))
    ap.add_argument("--check-sizes", default="2,1.4142136,1",
                    help="CalculiX free-free check at these Gmsh sizes (mm); empty: no check")
    ap.add_argument("--workdir", default="/tmp/sphere-lamb")
    args = ap.parse_args()

    R, cad = radius_from_step(args.hexfem, args.step)
    E, nu, rho = chain.E_MPA, chain.NU, chain.RHO_T_PER_MM3
    mu = E / (2 * (1 + nu))
    cs = math.sqrt(mu / rho)  # mm/s
    cp = cs * math.sqrt(moduli(nu)[0])
    hz = cs / (2 * math.pi * R)  # f = x * hz

    # enough modes for NREF with multiplicity, plus the next few for the table
    modes = lamb_modes(nu, 6.5)
    for m in modes:
        m["frequency_hz"] = m["x"] * hz
        # the independent closed form must vanish at the same root
        if m["kind"] == "spheroidal":
            f = lambda x, n=m["n"]: sato_usami(n, x, nu)  # noqa: E731
            key = "sato_usami_rel_diff"
        else:  # the torsional equation in its first form, x j_n' - j_n, scipy's derivative
            f = lambda x, n=m["n"]: x * jn(n, x, 1) - jn(n, x)  # noqa: E731
            key = "derivative_form_rel_diff"
        x2 = brentq(f, m["x"] * (1 - 1e-3), m["x"] * (1 + 1e-3), xtol=XTOL)
        m[key] = x2 / m["x"] - 1
    expanded = [m for m in modes for _ in range(m["multiplicity"])]
    ref = [m["frequency_hz"] for m in expanded[:NREF]]
    unc_rel = 10 * XTOL / 2.50  # brentq xtol over the smallest root, with margin
    print("R = %.6g mm, c_s = %.6g mm/s, c_p = %.6g mm/s, f = x * %.6f Hz" % (R, cs, cp, hz))
    print("%-11s %3s %3s %15s %14s %4s" % ("class", "n", "k", "x = wR/c_s", "f (Hz)", "mult"))
    for m in modes:
        print("%-11s %3d %3d %15.10f %14.4f %4d" % (m["kind"], m["n"], m["overtone"], m["x"],
                                                   m["frequency_hz"], m["multiplicity"]))

    # published: Lamb's ka/pi = .842 for the gravest second-order spheroidal mode
    s2 = next(m for m in modes if m["kind"] == "spheroidal" and m["n"] == 2)
    t2 = next(m for m in modes if m["kind"] == "torsional" and m["n"] == 2)
    s2_quarter = lamb_modes(0.25, 3.0, nmax=2)
    s2_q = next(m for m in s2_quarter if m["kind"] == "spheroidal" and m["n"] == 2)
    published = {
        "source": "Lamb (1882) p. 211: ka/pi = .842 for the slowest spheroidal mode of the "
                  "second order (k = omega / c_s, a = radius), quoted in "
                  "github.com/edur409/Circumferential-Surface-Waves Fundamental_Modes/README.md",
        "lamb_ka_over_pi": 0.842,
        "this_ka_over_pi_nu_0.3": s2["x"] / math.pi,
        "this_ka_over_pi_nu_0.25": s2_q["x"] / math.pi,
        "torsional_n2_ka_over_pi": t2["x"] / math.pi,
    }
    print("Lamb (1882) ka/pi = .842; here %.5f (nu = 0.3), %.5f (nu = 0.25)"
          % (s2["x"] / math.pi, s2_q["x"] / math.pi))

    doc = {
        "what": "sphere.stp (shared models; R %g mm), steel, free-free: analytic natural "
                "frequencies (Lamb 1882)" % R,
        "command": " ".join(["validation/reference/sphere_lamb.py"] + sys.argv[1:]),
        "geometry": args.step,
        "units": "mm, N, t (tonne), s: E in MPa, density in t/mm^3, frequencies in Hz",
        "material": {"E_MPa": E, "nu": nu, "density_t_per_mm3": rho},
        "boundary": "free-free (no fixed DOF); the six rigid-body modes dropped",
        "element": "analytic (Lamb 1882)",
        "radius_mm": R,
        "cad": cad,
        "wave_speeds_mm_per_s": {"c_s": cs, "c_p": cp},
        "equations": {
            "torsional": "(n - 1) j_n(x) - x j_{n+1}(x) = 0, n >= 1 (n = 1: x = 0 rigid, dropped)",
            "spheroidal": "det [[srr(P), srr(S)], [srt(P), srt(S)]] = 0 at r = R (see the "
                          "docstring); n = 0: tan y (4 - (c_p/c_s)^2 y^2) = 4 y; n = 1: x = 0 "
                          "rigid, dropped",
            "x": "omega R / c_s; y = omega R / c_p; f = x c_s / (2 pi R); multiplicity 2 n + 1",
        },
        "modes": modes,
        "reference_hz": ref,
        "reference_uncertainty_hz": [unc_rel * f for f in ref],
        "reference_uncertainty_rel": [unc_rel] * len(ref),
        "reference_modes": ["%s n=%d" % (m["kind"], m["n"]) for m in expanded[:NREF]],
        "check": {"published": published},
    }

    if args.check_sizes:
        sizes = sorted((float(v) for v in args.check_sizes.split(",")), reverse=True)
        os.makedirs(args.workdir, exist_ok=True)
        os.environ.setdefault("OMP_NUM_THREADS", "1")
        nmodes = 2 * NREF  # the next multiplets too, as a diagnostic
        cdoc = {"runs": [chain.run_size(args.step, h, args.workdir, "sphere_free", nmodes,
                                        free=True) for h in sizes]}
        cdoc = chain.summarize(cdoc, nref=nmodes)
        exact = [m["frequency_hz"] for m in expanded[:nmodes]]
        # the mesh splits each (2n+1)-fold root; the mean over a multiplet's sorted slots
        # compares the multiplet as a whole (whole multiplets within the nmodes only)
        slots, k = [], 0
        for m in modes:
            if k + m["multiplicity"] > nmodes:
                break
            slots.append(("%s n=%d" % (m["kind"], m["n"]), k, k + m["multiplicity"], m["frequency_hz"]))
            k += m["multiplicity"]
        rows = []
        for r in cdoc["runs"]:
            d = [f / e - 1 for f, e in zip(r["frequencies_hz"], exact)]
            means = {name: float(np.mean(r["frequencies_hz"][a:b])) / fe - 1 for name, a, b, fe in slots}
            rows.append({"h": r["h"], "dofs": r["dofs"], "elements": r["elements"],
                         "mesh_volume": r["mesh_volume"], "seconds_ccx": r["seconds_ccx"],
                         "rigid_hz": r["rigid_hz"], "frequencies_hz": r["frequencies_hz"],
                         "rel_diff": d, "max_abs_rel_diff_first_%d" % NREF:
                             max(abs(v) for v in d[:NREF]),
                         "multiplet_mean_rel_diff": means})
        dx = [f / e - 1 for f, e in zip(cdoc["reference_hz"], exact)]
        doc["check"]["calculix"] = {
            "what": "reference_chain.py free-free (Gmsh 4.8.4 P2 tets, ccx 2.20 C3D10, no "
                    "*BOUNDARY, six rigid modes checked and dropped); sorted frequencies against "
                    "the sorted analytic list with multiplicity",
            "versions": chain.tool_versions(),
            "runs": rows,
            "richardson": cdoc["richardson"],
            "richardson_hz": cdoc["reference_hz"],
            "richardson_rel_diff": dx,
            "richardson_max_abs_rel_diff_first_%d" % NREF: max(abs(v) for v in dx[:NREF]),
        }
        print("ccx, relative difference to Lamb (first %d):" % NREF)
        for r in rows:
            print("  h = %-8g %7d DOF  max %.2e  %s" % (r["h"], r["dofs"],
                                                      r["max_abs_rel_diff_first_%d" % NREF],
                                                      " ".join("%+.1e" % v for v in r["rel_diff"][:NREF])))
            print("      multiplet means: " + ", ".join("%s %+.1e" % kv for kv in
                                                      r["multiplet_mean_rel_diff"].items()))
        print("  Richardson        max %.2e  %s" % (max(abs(v) for v in dx[:NREF]),
                                                   " ".join("%+.1e" % v for v in dx[:NREF])))
    with open(args.out, "w") as f:
        json.dump(doc, f, indent=2)
        f.write("\n")
    print("wrote", args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
