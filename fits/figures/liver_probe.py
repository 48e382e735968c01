"""The picture of data/scenes/liver_probe.json (make figures): the last step's body_NNNN.vtu of
DIR read by VTK's reader (Debian's python3-vtk9), its boundary surface coloured by the
displacement's magnitude, drawn by gnuplot (no display needed) into a PNG.

usage: python3 fits/figures/liver_probe.py DIR OUT.png
"""
import glob
import math
import subprocess
import sys
import tempfile

from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader
from vtkmodules.vtkFiltersGeometry import vtkGeometryFilter

if len(sys.argv) != 3:
    sys.exit("usage: python3 fits/figures/liver_probe.py DIR OUT.png")
folder, out = sys.argv[1], sys.argv[2]
# the output name goes into gnuplot's script inside quotes: a name that could end the quotes or
# the line (and so become a gnuplot command) is refused, not escaped
if any(ch in out for ch in "'\"`\\\n\r;") or not out:
    sys.stderr.write("liver_probe.py: output name %r: quotes, backslashes, semicolons and "
                     "line breaks are not allowed\n" % out)
    sys.exit(2)
steps = sorted(glob.glob(glob.escape(folder) + "/body_*.vtu"))
if not steps:
    sys.stderr.write("liver_probe.py: %s: no body_*.vtu (run conifit simulate ... --vtu DIR)\n"
                     % folder)
    sys.exit(66)
last = steps[-1]
reader = vtkXMLUnstructuredGridReader()
reader.SetFileName(last)
reader.Update()
grid = reader.GetOutput()
surface = vtkGeometryFilter()
surface.SetInputData(grid)
surface.Update()
poly = surface.GetOutput()
disp = poly.GetPointData().GetArray("displacement")
mag = [math.sqrt(sum(disp.GetComponent(i, k) ** 2 for k in range(3)))
       for i in range(poly.GetNumberOfPoints())]
if not mag or not all(math.isfinite(m) for m in mag):
    sys.stderr.write("liver_probe.py: %s: no finite displacement to draw\n" % last)
    sys.exit(65)
top = max(mag) or 1.0
with tempfile.NamedTemporaryFile("w", suffix=".dat", delete=False) as dat:
    # each triangle as a degenerate pm3d quadrangle: two scans of two points
    for c in range(poly.GetNumberOfCells()):
        ids = poly.GetCell(c).GetPointIds()
        if ids.GetNumberOfIds() != 3:
            continue
        pts = [ids.GetId(k) for k in range(3)]
        v = sum(mag[p] for p in pts) / 3
        rows = [(pts[0], pts[1]), (pts[2], pts[2])]
        for scan in rows:
            for p in scan:
                x, y, z = poly.GetPoint(p)
                dat.write("%.6g %.6g %.6g %.6g\n" % (x, y, z, v))
            dat.write("\n")
        dat.write("\n")
script = """set terminal pngcairo size 900,600 font ',11'
set output '%s'
set view 60, 20, 1.3, 1.0
set view equal xyz
unset border; unset tics; unset key
set title "liver2.msh: the fitted muscle spring on every edge, a flat punch 8 mm in (colour: |u|, 0 to %.2f mm)"
set pm3d depthorder lighting primary 0.5 specular 0.2
set palette rgb 33,13,10
set cbrange [0:%.6g]
set colorbox
set cbtics
set cblabel '|u|, mm'
splot '%s' using 1:2:3:4 with pm3d
""" % (out, top, top, dat.name)
subprocess.run(["gnuplot"], input=script, text=True, check=True)
