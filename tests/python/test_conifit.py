"""The Python module (src/python/conifit.py) against the conifit binary: the same law, fit,
scene and export through ctypes as through the command line, and the library's refusals raised
as conifit.Error with its message. Run by tests/cli/test_python.c (which sets CONIFIT, the
binary, and CONIFIT_LIBRARY, the shared library of the same build)."""

import array
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

    def test_non_finite_displacements_are_refused(self):
        for bad, word in ((float("nan"), "not a number"), (float("inf"), "+infinity"),
                          (float("-inf"), "-infinity")):
            for spring in (SPRING, SPRING + [0, 0]):
                with self.assertRaises(conifit.Error) as c:
                    conifit.force(spring, [1.0, bad])
                self.assertEqual(c.exception.status, "data")
                self.assertIn("displacement 1", str(c.exception))
                self.assertIn(word, str(c.exception))
        with self.assertRaises(conifit.Error) as c:  # an int beyond a double: no OverflowError
            conifit.force(SPRING, [1, 10 ** 400])
        self.assertIn("u_mm[1]", str(c.exception))
        with self.assertRaises(conifit.Error) as c:
            conifit.force(SPRING[:5] + [10 ** 400], [1])
        self.assertIn("spring[5]", str(c.exception))

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

    def test_a_fit_of_sequences_names_no_deleted_file(self):
        # the fit reads a temporary table it deletes before returning: the result must not name
        # it (an earlier version's data.file did), and keeps the data it was given
        x = [0.01 * i for i in range(1, 21)]
        y = [10 * e + 40 * e ** 3 for e in x]
        got = conifit.fit(strain=x, stress=y, stress_unit="kPa", type="telescoping")
        data = got["data"]
        self.assertIsNone(data["file"])
        self.assertIn("sequences", data["source"])
        self.assertEqual(data["strain"], x)
        self.assertEqual(data["stress"], y)
        self.assertEqual(data["points"], 20)
        text = json.dumps(got)
        self.assertNotIn(tempfile.gettempdir() + "/conifit-", text)
        self.assertNotIn(".csv", text)

    def test_a_table_whose_f_quantile_gsl_cannot_invert(self):
        # 274 rows: the F-test's F(0.95; 1, 271), whose inverse GSL 2.7 does not converge; with
        # GSL's default handler (Python never turns it off) this session was killed by abort()
        x = [0.5 * (i + 1) / 274 for i in range(274)]
        y = [10 * e + 40 * e ** 3 for e in x]
        got = conifit.fit(strain=x, stress=y)
        self.assertEqual(len(got["fits"]), 2)
        self.assertEqual(got["data"]["points"], 274)

    def test_strings_with_a_nul_are_refused(self):
        for call in (lambda: conifit.fit(self.TABLE + "\0x"),
                     lambda: conifit.fit(self.TABLE, type="telescoping\0x"),
                     lambda: conifit.force(SPRING, [1], method="closed\0x"),
                     lambda: conifit.simulate("data/scenes/uniaxial.json\0x"),
                     lambda: conifit.export(self.TABLE, "csv\0x")):
            with self.assertRaises(conifit.Error) as c:
                call()
            self.assertEqual(c.exception.status, "usage")
            self.assertIn("NUL", str(c.exception))

    def test_refusals_of_sequences_name_the_value_not_a_temporary(self):
        x = [0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6]
        y = [0, 1, 2, float("nan"), 4, 5, 6]
        with self.assertRaises(conifit.Error) as c:
            conifit.fit(strain=x, stress=y)
        self.assertEqual(c.exception.status, "data")
        self.assertTrue(str(c.exception).startswith("stress[3]: "), str(c.exception))
        self.assertNotIn(tempfile.gettempdir(), str(c.exception))
        with self.assertRaises(conifit.Error) as c:
            conifit.fit(strain=[0, 0.1], stress=[0, 1])
        self.assertTrue(str(c.exception).startswith("strain, stress: "), str(c.exception))
        self.assertNotIn(".csv", str(c.exception))
        with self.assertRaises(conifit.Error) as c:
            conifit.fit(strain=x[:6] + [10 ** 400], stress=y)
        self.assertIn("strain[6]", str(c.exception))

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
        cols = conifit.simulate(scene)
        theirs = list(csv.DictReader(io.StringIO(run("simulate", scene, "-o", "-", "-q"))))
        # columns, not a dict a sample: 8 bytes a number (1 for stable)
        self.assertEqual(sorted(cols), sorted(theirs[0]))
        for key, col in cols.items():
            self.assertIsInstance(col, array.array)
            self.assertEqual(col.typecode, "b" if key == "stable" else "d")
            self.assertEqual(len(col), len(theirs))
        for i, b in enumerate(theirs):
            for key in ("time_s", "strain", "stress_kPa", "spring_stress_kPa"):
                a = cols[key][i]
                self.assertTrue(abs(a - float(b[key])) <= 1e-9 * max(1, abs(float(b[key]))),
                                (key, i, a, b[key]))
            self.assertEqual(cols["stable"][i], int(b["stable"]))
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
            with self.assertRaises(conifit.Error) as c:
                conifit.export(fit, "csv", tol=10 ** 400)
            self.assertIn("tol", str(c.exception))

    def test_a_tail_too_stiff_to_tabulate_is_refused(self):
        # n_tail 1e-15: the table grew without bound (15 GB after 200 s)
        spring = run("export", "fits/telescoping.json", "--format", "json", "-q")
        doc = json.loads(spring)
        doc["params"].update(D1_mm=10, D2_mm=30, n=4, d_mm=1, G_MPa=80000, H_mm=50,
                             n_tail=1e-15, H_tail_mm=10)
        doc.pop("derived")
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "stiff.json")
            with open(path, "w") as f:
                json.dump(doc, f)
            with self.assertRaises(conifit.Error) as c:
                conifit.export(path, "csv")
            self.assertEqual(c.exception.status, "data")
            self.assertIn("n_tail = 1e-15", str(c.exception))


if __name__ == "__main__":
    unittest.main(verbosity=1)
