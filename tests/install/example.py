"""The Python module as installed (tests/install/run.sh runs it with the staged tree on
PYTHONPATH): forces against the installed binary's, and a refusal raised with the library's
message. Argument: the installed conifit binary."""
import subprocess
import sys

import conifit

binary = sys.argv[1]
spring = [4, 12, 5, 0.8, 80000, 10]
us = [-2, 0.5, 3, 8]
for u, f in zip(us, conifit.force(spring, us)):
    want = float(subprocess.run([binary, "force", "--D1", "4", "--D2", "12", "--n", "5", "--d", "0.8",
                                 "--G", "80000", "--H", "10", "--u", str(u)],
                                check=True, capture_output=True, text=True).stdout)
    assert abs(f - want) <= 1e-12 * max(1, abs(want)), (u, f, want)
try:
    conifit.force([4, 12, 1, 0.8, 80000, 10], [1])
except conifit.Error as e:
    assert e.status == "data" and "n" in str(e), str(e)
else:
    raise SystemExit("a spring of 1 coil was accepted")
print("python module from", conifit.library_path, "ok")
