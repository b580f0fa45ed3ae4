"""UCS, Brazilian tensile strength and their ratio for each model run by
strength_ratio.sh: UCS = peak of the mean platen force over the cylinder's
cross-section; T = 2 P / (pi D t) at the peak load P (ISRM Brazilian test);
E = secant modulus at half the peak (gauge length from ucs_info.txt);
nu = slope of the lateral strain against the axial strain between 20 and
50 % of the peak on the loading branch (the calibrate stage's window,
post::AnalyseUcs);
K_IC of the semi-circular bend test when it ran (Kuruppu et al. 2014,
eqs. 1-2, as post::ScbToughness)."""
import math
import os
import sys


def info(path):
    words = open(path).read().split()
    return {words[i]: words[i + 1] for i in range(len(words) - 1)}


def curve(path):
    rows = []
    for line in open(path):
        if line.startswith("#") or not line.strip():
            continue
        rows.append([float(v) for v in line.split()])
    return rows


def analyse(out, model):
    """UCS, T, E, peaked and K_IC; None for a test that did not run."""
    if not os.path.exists(f"{out}/{model}/ucs/ucs_info.txt"):
        return None, None, None, None, None, toughness(out, model)
    ui = info(f"{out}/{model}/ucs/ucs_info.txt")
    uc = curve(f"{out}/{model}/ucs/ucs_curve.txt")
    d = float(ui["diameter"])
    area = math.pi * d * d / 4
    gauge = float(ui["gauge_length"])
    stress = [0.5 * (r[3] + r[4]) / area for r in uc]
    strain = [r[2] / gauge for r in uc]
    k = max(range(len(stress)), key=lambda i: stress[i])
    ucs = stress[k]
    half = next(i for i in range(len(stress)) if stress[i] >= 0.5 * ucs)
    young = stress[half] / strain[half]
    tensile = None  # the Brazilian test did not run (tests="ucs tension ...")
    if os.path.exists(f"{out}/{model}/brazilian/brazilian_info.txt"):
        bi = info(f"{out}/{model}/brazilian/brazilian_info.txt")
        bc = curve(f"{out}/{model}/brazilian/brazilian_curve.txt")
        load = max(0.5 * (r[3] + r[4]) for r in bc)
        tensile = 2 * load / (math.pi * float(bi["diameter"]) * float(bi["thickness"]))
    peaked = k + 1 < len(stress)
    return ucs, tensile, young, poisson(stress, strain, [r[5] for r in uc], k), peaked, \
        toughness(out, model)


def poisson(stress, strain, lateral, k):
    """Least-squares slope of lateral against axial strain over the loading
    points between 20 and 50 % of the peak stress (post::AnalyseUcs)."""
    lo, hi = 0.2 * stress[k], 0.5 * stress[k]
    first = next(i for i in range(k + 1) if stress[i] >= lo)
    idx = [i for i in range(first, k + 1) if stress[i] <= hi]
    if len(idx) < 3:
        return None
    idx = list(range(idx[0], idx[-1] + 1))
    mx = sum(strain[i] for i in idx) / len(idx)
    my = sum(lateral[i] for i in idx) / len(idx)
    sxx = sum((strain[i] - mx) ** 2 for i in idx)
    sxy = sum((strain[i] - mx) * (lateral[i] - my) for i in idx)
    return sxy / sxx if sxx > 0 else None


def direct_tension(out, model):
    """Direct tensile strength: the peak of the mean grip force over the
    cylinder's cross-section; None when the tension test did not run."""
    try:
        ti = info(f"{out}/{model}/tension/tension_info.txt")
    except FileNotFoundError:
        return None
    tc = curve(f"{out}/{model}/tension/tension_curve.txt")
    d = float(ti["diameter"])
    return max(0.5 * (r[3] + r[4]) for r in tc) / (math.pi * d * d / 4)


def toughness(out, model):
    """K_IC = Y' P sqrt(pi a) / (2 R B), Y' of Kuruppu et al. (2014), eq. 2;
    None when the SCB test did not run."""
    try:
        si = info(f"{out}/{model}/scb/scb_info.txt")
    except FileNotFoundError:
        return None
    sc = curve(f"{out}/{model}/scb/scb_curve.txt")
    load = max(0.5 * (r[3] + r[4]) for r in sc)
    r, b = float(si["radius"]), float(si["thickness"])
    a, s = float(si["notch"]), float(si["half_span"])
    beta, sr = a / r, s / r
    y = -1.297 + 9.516 * sr - (0.47 + 16.457 * sr) * beta + (1.071 + 34.401 * sr) * beta ** 2
    return y * load * math.sqrt(math.pi * a) / (2 * r * b)


def main():
    out, models = sys.argv[1], sys.argv[2:]
    print("| model | UCS [MPa] | tensile [MPa] | UCS/T | E (secant at UCS/2) [GPa] | nu "
          "| UCS peaked | K_IC [MPa m^0.5] | direct tension [MPa] | UCS/direct |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for m in models:
        ucs, t, e, nu, peaked, k = analyse(out, m)
        kic = "-" if k is None else f"{k / 1e6:.3f}"
        dt = direct_tension(out, m)
        dts = "-" if dt is None else f"{dt / 1e6:.2f}"
        ratio = "-" if dt is None or ucs is None else f"{ucs / dt:.2f}"
        if ucs is None:
            print(f"| {m} | - | - | - | - | - | - | {kic} | {dts} | - |")
            continue
        nus = "-" if nu is None else f"{nu:.3f}"
        ts = "-" if t is None else f"{t / 1e6:.2f}"
        rt = "-" if t is None else f"{ucs / t:.2f}"
        print(f"| {m} | {ucs / 1e6:.1f} | {ts} | {rt} | {e / 1e9:.1f} | {nus} | "
              f"{'yes' if peaked else 'no (cap reached)'} | {kic} | {dts} | {ratio} |")


if __name__ == "__main__":
    main()
