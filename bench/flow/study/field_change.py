#!/usr/bin/python3
"""Where does a steady solve still change? Compares two written iterations of
a flow case and bins the change of U and p, and the initial residual of p,
by region of the default mill (axis at x = 0, y = 1.2 m; rotor zone radius
0.575 m), then lists the cells that changed most.

Before: the case's controlDict needs a `solverInfo` function object with
`writeResidualFields yes` (fields (U p)) and a writeInterval that keeps the
two iterations; then, in the case (after reconstructPar if it ran in
parallel):

    foamToVTK -time '600,700' -fields '(U p initialResidual:p)' \
              -noFaceZones -excludePatches '(".*")'
    bench/flow/study/field_change.py <case> 600 700

Used for docs/flow.md, "Where the rotor zone ends"."""
import sys, glob, numpy as np, vtk
from vtk.util.numpy_support import vtk_to_numpy as v2n
case, t1, t2 = sys.argv[1], sys.argv[2], sys.argv[3]
def load(t):
    f = sorted(glob.glob(f"{case}/VTK/*_{t}.vtu") + glob.glob(f"{case}/VTK/*_{t}/internal.vtu"))
    if not f:
        f = [g for g in glob.glob(f"{case}/VTK/**/*.vtu", recursive=True) if f"_{t}" in g and "internal" in g]
    r = vtk.vtkXMLUnstructuredGridReader(); r.SetFileName(f[0]); r.Update()
    g = r.GetOutput()
    cc = vtk.vtkCellCenters(); cc.SetInputData(g); cc.Update()
    X = v2n(cc.GetOutput().GetPoints().GetData())
    vol = vtk.vtkCellSizeFilter(); vol.SetInputData(g); vol.ComputeVolumeOn(); vol.Update()
    V = v2n(vol.GetOutput().GetCellData().GetArray("Volume"))
    cd = g.GetCellData()
    d = {cd.GetArrayName(i): v2n(cd.GetArray(i)) for i in range(cd.GetNumberOfArrays())}
    return X, V, d
X, V, a = load(t1); _, _, b = load(t2)
dU = np.linalg.norm(b["U"] - a["U"], axis=1)
dp = np.abs(b["p"] - a["p"])
r = np.hypot(X[:,0], X[:,1]-1.2)
regions = {
 "r < 0.575 m (rotor zone radius)": r < 0.575,
 "ring 0.575<r<0.8 (beside rotor)": (r >= 0.575) & (r < 0.8) ,
 "below rotor y<0.6": (X[:,1] < 0.6) & (r >= 0.575),
 "mid 0.6<y<2.0 outside ring": (X[:,1] >= 0.6) & (X[:,1] < 2.0) & (r >= 0.8),
 "upper 2.0<y<3.5": (X[:,1] >= 2.0) & (X[:,1] < 3.5),
 "top y>3.5 (inlet)": X[:,1] >= 3.5,
}
res = [k for k in b if k.startswith("initialResidual")]
print(f"cells {len(V)}; times {t1}->{t2}; total volume {V.sum():.3f} m3")
print(f"{'region':36s} {'vol%':>6s} {'cells':>7s} {'share of sum dU*V':>18s} {'mean dU':>8s} {'max dU':>8s} {'share dp*V':>10s} " + " ".join(f"{'share of ' + k.split(':')[-1] + ' residual':>22s}" for k in res))
tot = (dU*V).sum(); totp = (dp*V).sum()
for name, m in regions.items():
    line = f"{name:36s} {100*V[m].sum()/V.sum():6.1f} {m.sum():7d} {100*(dU[m]*V[m]).sum()/tot:17.1f}% {np.average(dU[m],weights=V[m]):8.3f} {dU[m].max():8.3f} {100*(dp[m]*V[m]).sum()/totp:9.1f}% "
    for k in res:
        rr = np.abs(b[k]) if b[k].ndim==1 else np.abs(b[k]).max(axis=1)
        line += f" {100*rr[m].sum()/rr.sum():9.1f}%"
    print(line)
i = np.argsort(-dU)[:15]
print("largest |dU| cells: x y z r dU U2")
for j in i: print(f"{X[j,0]:7.3f} {X[j,1]:7.3f} {X[j,2]:7.3f} {r[j]:6.3f} {dU[j]:8.2f} {np.linalg.norm(b['U'][j]):8.2f}")
for k in res:
    rr = np.abs(b[k]) if b[k].ndim==1 else np.abs(b[k]).max(axis=1)
    i = np.argsort(-rr)[:8]
    print(f"largest {k}:")
    for j in i: print(f"  {X[j,0]:7.3f} {X[j,1]:7.3f} {X[j,2]:7.3f} r={r[j]:6.3f} res={rr[j]:.3g} vol={V[j]:.2e}")
