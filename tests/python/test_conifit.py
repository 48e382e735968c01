"""The Python module (src/python/conifit.py) against the conifit binary: the same law, fit,
scene and export through ctypes as through the command line, and the library's refusals raised
as conifit.Error with its message. Run by tests/cli/test_python.c (which sets CONIFIT, the
binary, and CONIFIT_LIBRARY, the shared library of the same build)."""

import csv
import io
import json
import os
import subprocess
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "src", "python"))
import conifit  # noqa: E402

BIN = os.environ.get("CONIFIT", "build/conifit")
SPRING = [4, 12, 5, 0.8, 80000, 10]
FLAGS = ["--D1", "4", "--D2", "12", "--n", "5", "--d", "0.8", "--G", "80000", "--H", "10"]


def run(*args):
    return subprocess.run([BIN, *args], check=True, capture_output=True, text=True).stdout


def close(a, b, rel):
    return abs(a - b) <= rel * max(abs(a), abs(b), 1e-300)


class Law(unittest.TestCase):
    def test_force_matches_binary(self):
        us = [-3, -0.5, 0, 0.4, 1.5, 4, 7.25, 9.1, 12]
        for method in ("closed", "exact", "table"):
            F, k = conifit.force(SPRING, us, method=method, stiffness=True)
            self.assertEqual(len(F), len(us))
            for u, f, kk in zip(us, F, k):
                want = float(run("force", *FLAGS, "--u", str(u), "--method", method))
                self.assertTrue(close(f, want, 1e-9), "%s F(%g) = %r, binary %r" % (method, u, f, want))
                self.assertGreaterEqual(kk, 0)
        self.assertEqual(conifit.force(SPRING, []), [])

    def test_a_tailed_spring_matches_binary(self):
        tail = [10, 30, 4, 1, 80000, 40, 1, 10]
        flags = ["--D1", "10", "--D2", "30", "--n", "4", "--d", "1", "--G", "80000", "--H", "40",
                 "--n_tail", "1", "--H_tail", "10"]
        us = [-37.5, -20, 5, 20, 36, 37, 38, 39]  # region 3 from 36.25, solid at 38 mm
        for method in ("closed", "exact", "table"):
            F = conifit.force(tail, us, method=method)
            for u, f in zip(us, F):
                want = float(run("force", *flags, "--u", str(u), "--method", method))
                self.assertTrue(close(f, want, 1e-12), "%s F(%g) = %r, binary %r" % (method, u, f, want))
        self.assertEqual(conifit.force(tail, [37])[0], 80.0)
        self.assertEqual(conifit.force(tail[:6] + [0, 0], us), conifit.force(tail[:6], us))
        with self.assertRaises(conifit.Error) as c:
            conifit.force(tail[:6] + [-1, 10], [1])
        self.assertIn("n_tail", str(c.exception))

    def test_bad_spring_raises_library_message(self):
        with self.assertRaises(conifit.Error) as c:
            conifit.force([4, 2, 5, 0.8, 80000, 10], [1])
        self.assertEqual(c.exception.status, "data")
        self.assertIn("D1_mm = 4 must not exceed D2_mm = 2", str(c.exception))
        with self.assertRaises(conifit.Error) as c:
            conifit.force(SPRING, [1], method="fast")
        self.assertIn("fast", str(c.exception))
        with self.assertRaises(conifit.Error):
            conifit.force(SPRING[:5], [1])
        with self.assertRaises(conifit.Error):
            conifit.force(SPRING, ["x"])


class Fit(unittest.TestCase):
    TABLE = "data/telescoping_noise1pct.csv"

    def test_path_matches_binary(self):
        mine = conifit.fit(self.TABLE)
        theirs = json.loads(run("fit", self.TABLE, "-o", "-"))
        self.assertEqual([f["type"] for f in mine["fits"]], [f["type"] for f in theirs["fits"]])
        for a, b in zip(mine["fits"], theirs["fits"]):
            for key, value in b["params"].items():
                self.assertTrue(close(a["params"][key], value, 1e-6), (key, a["params"][key], value))
        self.assertEqual(mine["data"]["points"], theirs["data"]["points"])

    def test_validate_matches_binary(self):
        mine = conifit.fit(self.TABLE, validate=True)
        theirs = json.loads(run("fit", self.TABLE, "--validate", "-o", "-"))
        for a, b in zip(mine["fits"], theirs["fits"]):
            self.assertTrue(close(a["validation"]["rmse"], b["validation"]["rmse"], 1e-6),
                            (a["validation"]["rmse"], b["validation"]["rmse"]))
        self.assertNotIn("validation", conifit.fit(self.TABLE)["fits"][0])

    def test_sequences_equal_path(self):
        with open(self.TABLE) as f:
            rows = [r for r in csv.reader(line for line in f if not line.startswith("#"))]
        self.assertEqual(rows[0], ["strain", "stress_kPa"])
        x = [float(r[0]) for r in rows[1:]]
        y = [float(r[1]) for r in rows[1:]]
        a = conifit.fit(strain=x, stress=y, stress_unit="kPa", type="telescoping")
        b = conifit.fit(self.TABLE, type="telescoping")
        self.assertEqual(len(a["fits"]), 1)
        for key, value in b["fits"][0]["params"].items():
            self.assertTrue(close(a["fits"][0]["params"][key], value, 1e-9), key)

    def test_errors(self):
        with self.assertRaises(conifit.Error) as c:
            conifit.fit("no/such/table.csv")
        self.assertEqual(c.exception.status, "noinput")
        self.assertIn("no/such/table.csv", str(c.exception))
        with self.assertRaises(conifit.Error) as c:
            conifit.fit(strain=[0, 0.1], stress=[0, 1])
        self.assertEqual(c.exception.status, "data")
        with self.assertRaises(conifit.Error):
            conifit.fit(strain=[0, 0.1, 0.2], stress=[0, 1])
        with self.assertRaises(conifit.Error):
            conifit.fit(self.TABLE, type="helical")


class Scene(unittest.TestCase):
    def test_simulate_matches_binary(self):
        scene = "data/scenes/uniaxial.json"
        rows = conifit.simulate(scene)
        theirs = list(csv.DictReader(io.StringIO(run("simulate", scene, "-o", "-", "-q"))))
        self.assertEqual(len(rows), len(theirs))
        for a, b in zip(rows, theirs):
            for key in ("time_s", "strain", "stress_kPa", "spring_stress_kPa"):
                self.assertTrue(abs(a[key] - float(b[key])) <= 1e-9 * max(1, abs(float(b[key]))),
                                (key, a[key], b[key]))
            self.assertEqual(a["stable"], int(b["stable"]))
        with self.assertRaises(conifit.Error) as c:
            conifit.simulate("no/such/scene.json")
        self.assertEqual(c.exception.status, "noinput")

    def test_scene_above_the_budget_is_refused(self):
        with open("data/scenes/uniaxial.json") as f:
            scene = json.load(f)
        scene["lattice"].update(nx=400, ny=400, nz=400)
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "huge.json")
            with open(path, "w") as f:
                json.dump(scene, f)
            with self.assertRaises(conifit.Error) as c:
                conifit.simulate(path)
            self.assertEqual(c.exception.status, "data")
            theirs = subprocess.run([BIN, "simulate", path, "-o", os.path.join(d, "out.csv")],
                                    capture_output=True, text=True)
            self.assertEqual(theirs.returncode, 65)
            self.assertIn(str(c.exception), theirs.stderr)


class Export(unittest.TestCase):
    def test_export_matches_binary(self):
        with tempfile.TemporaryDirectory() as d:
            fit = os.path.join(d, "fit.json")
            with open(fit, "w") as f:
                json.dump(conifit.fit("data/non_telescoping.csv"), f)
            for fmt in ("csv", "calculix", "json"):
                mine = conifit.export(fit, fmt).splitlines()
                theirs = run("export", fit, "--format", fmt, "-q").splitlines()
                self.assertEqual(len(mine), len(theirs), fmt)
                self.assertGreater(len(mine), 5)
            with self.assertRaises(conifit.Error) as c:
                conifit.export(fit, "nastran")
            self.assertIn("nastran", str(c.exception))
            with self.assertRaises(conifit.Error):
                conifit.export(fit, "csv", tol=5)


if __name__ == "__main__":
    unittest.main(verbosity=1)
