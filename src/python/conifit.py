"""conifit from Python: the conical-spring law, fits, scenes and exports of libconifit.

Standard library only: ctypes over libconifit.so (the flat calls of conifit/flat.h).

    import conifit
    conifit.force([4, 12, 5, 0.8, 80000, 10], [0.5, 1.5, 3.0])   # N at each compression (mm)
    fit = conifit.fit("data/telescoping_noise1pct.csv")          # the fit file, as a dict
    fit = conifit.fit(strain=[...], stress=[...], stress_unit="kPa")
    cols = conifit.simulate("data/scenes/uniaxial.json")           # dict of columns (array.array)
    text = conifit.export("fit.json", "calculix")                  # the exported block

Every failure raises conifit.Error with the library's message and its status (.status: "usage",
"data", "noinput", "cantwrite", "internal", "noconv").

The library is looked for in the environment variable CONIFIT_LIBRARY (a path), then in the
folder it was installed into, then in the build folder of a source tree holding this file
(src/python/ beside build/), then by the system's loader (libconifit.so.0).
"""

import array
import ctypes
import json
import os
import re
import tempfile

__all__ = ["Error", "force", "fit", "simulate", "export", "library_path"]

# Set by make install to the folder the library went to.
_INSTALLED_LIBDIR = ""
_SONAME = "libconifit.so.0"
_MSG_LEN = 512  # CF_ERROR_MSG_LEN
_STATUS = {-1: "usage", -2: "data", -3: "noinput", -4: "cantwrite", -5: "internal", -6: "noconv"}
_SAMPLE_KEYS = ("time_s", "strain", "stress_kPa", "kinetic_energy_mJ", "spring_stress_kPa",
                "stable", "lateral_stretch")


class Error(Exception):
    """A refusal or failure of libconifit: str() is its message, .status its kind."""

    def __init__(self, status, message):
        self.status = _STATUS.get(status, "internal")
        super().__init__(message)


class _CfError(ctypes.Structure):
    _fields_ = [("status", ctypes.c_int), ("msg", ctypes.c_char * _MSG_LEN)]


def _candidates():
    env = os.environ.get("CONIFIT_LIBRARY")
    if env:
        return [env]
    here = os.path.dirname(os.path.abspath(__file__))
    found = []
    if _INSTALLED_LIBDIR:
        found.append(os.path.join(_INSTALLED_LIBDIR, _SONAME))
    found.append(os.path.join(here, "..", "..", "build", "libconifit.so"))
    found.append(_SONAME)
    return found


def _load():
    tried = []
    for path in _candidates():
        if os.sep in path and not os.path.exists(path):
            tried.append(path + " (absent)")
            continue
        try:
            lib = ctypes.CDLL(path)
        except OSError as e:
            tried.append("%s (%s)" % (path, e))
            continue
        return path, _declare(lib)
    raise ImportError("conifit: cannot load libconifit: tried " + "; ".join(tried))


def _declare(lib):
    dp = ctypes.POINTER(ctypes.c_double)
    err = ctypes.POINTER(_CfError)
    lib.cf_flat_force.argtypes = [dp, ctypes.c_char_p, ctypes.c_size_t, dp, dp, dp, err]
    lib.cf_flat_force_tail.argtypes = [dp, ctypes.c_char_p, ctypes.c_size_t, dp, dp, dp, err]
    lib.cf_flat_fit.argtypes = [ctypes.c_char_p, ctypes.c_char_p, ctypes.c_int,
                                ctypes.POINTER(ctypes.c_void_p), err]
    lib.cf_flat_simulate.argtypes = [ctypes.c_char_p, ctypes.POINTER(dp),
                                     ctypes.POINTER(ctypes.c_size_t), err]
    lib.cf_flat_export.argtypes = [ctypes.c_char_p, ctypes.c_char_p, ctypes.c_char_p,
                                   ctypes.c_double, ctypes.POINTER(ctypes.c_void_p), err]
    lib.cf_flat_free.argtypes = [ctypes.c_void_p]
    lib.cf_flat_free.restype = None
    for name in ("cf_flat_force", "cf_flat_force_tail", "cf_flat_fit", "cf_flat_simulate",
                 "cf_flat_export"):
        getattr(lib, name).restype = ctypes.c_int
    return lib


library_path, _lib = _load()


def _check(status, e):
    if status != 0:
        raise Error(status, e.msg.decode("utf-8", "replace"))


def _text(s, what):
    if s is None:
        return None
    if not isinstance(s, (str, bytes, os.PathLike)):
        raise Error(-1, "%s must be a string, not %s" % (what, type(s).__name__))
    b = os.fsencode(s)
    if b"\0" in b:
        # C reads a string up to its first NUL: the rest would be dropped without a word
        raise Error(-1, "%s holds a NUL character (at %d): %r" % (what, b.index(b"\0"), s))
    return b


def _taken(p):
    """The malloc'd text at p as a str, released."""
    try:
        return ctypes.string_at(p).decode("utf-8")
    finally:
        _lib.cf_flat_free(p)


def _number(v, what):
    try:
        return float(v)
    except OverflowError:
        raise Error(-2, "%s is too large for a floating-point number (beyond 1.8e308)"
                    % what) from None
    except (TypeError, ValueError):
        raise Error(-2, "%s must be a number, not %r" % (what, v)) from None


def _numbers(values, what):
    try:
        items = list(values)
    except TypeError:
        raise Error(-2, "%s must be a sequence of numbers" % what) from None
    return [_number(v, "%s[%d]" % (what, i)) for i, v in enumerate(items)]


def force(spring, u_mm, method="closed", stiffness=False):
    """Force (N) of the spring [D1, D2, n, d, G, H] (mm, MPa), or [D1, D2, n, d, G, H, n_tail,
    H_tail] for a spring with a cylindrical tail, at each compression in u_mm (mm, > 0 shortens);
    with stiffness=True a pair of lists (forces, tangent stiffnesses in N/mm)."""
    p = _numbers(spring, "spring")
    if len(p) not in (6, 8):
        raise Error(-1, "the spring needs 6 numbers (D1, D2, n, d, G, H) or 8 (and n_tail, "
                        "H_tail), got %d" % len(p))
    u = _numbers(u_mm, "u_mm")
    n = len(u)
    arr = ctypes.c_double * max(n, 1)
    F, k = arr(), arr()
    e = _CfError()
    call = _lib.cf_flat_force if len(p) == 6 else _lib.cf_flat_force_tail
    _check(call((ctypes.c_double * len(p))(*p), _text(method, "method"), n, arr(*u), F,
                k if stiffness else None, ctypes.byref(e)), e)
    if stiffness:
        return list(F[:n]), list(k[:n])
    return list(F[:n])


def fit(table=None, strain=None, stress=None, stress_unit="kPa", type="both", validate=False):
    """Fits a table (a path) or two sequences (strain, stress in stress_unit) as conifit fit
    does and returns the fit file's content as a dict. From sequences, the data section names no
    file (its "file" is None, its "source" says where the data came from) and holds the
    sequences as "strain" and "stress" (in stress_unit); no text of the result names the
    temporary table the fit read."""
    if table is not None and (strain is not None or stress is not None):
        raise Error(-1, "give a table path or strain and stress, not both")
    tmp = None
    if table is None:
        if strain is None or stress is None:
            raise Error(-1, "give a table path, or strain and stress")
        x, y = _numbers(strain, "strain"), _numbers(stress, "stress")
        if len(x) != len(y):
            raise Error(-2, "strain has %d values, stress %d" % (len(x), len(y)))
        if not isinstance(stress_unit, str) or not stress_unit.replace("/", "").isalnum():
            raise Error(-1, "stress_unit must be a unit name such as kPa")
        fd, tmp = tempfile.mkstemp(prefix="conifit-", suffix=".csv")
        with os.fdopen(fd, "w") as f:
            f.write("strain,stress_%s\n" % stress_unit)
            for a, b in zip(x, y):
                f.write("%.17g,%.17g\n" % (a, b))
        table = tmp
    try:
        out = ctypes.c_void_p()
        e = _CfError()
        _check(_lib.cf_flat_fit(_text(table, "table"), _text(type, "type"), 1 if validate else 0,
                                ctypes.byref(out), ctypes.byref(e)), e)
        result = json.loads(_taken(out))
        if tmp:
            result = _from_sequences(result, tmp, x, y, stress_unit)
        return result
    except Error as err:
        if not tmp:
            raise
        raise _in_sequences(err, tmp, len(x)) from None
    finally:
        if tmp:
            os.unlink(tmp)


def _from_sequences(result, tmp, x, y, stress_unit):
    """The fit of the temporary table tmp told as a fit of the sequences x, y: every text naming
    tmp names the sequences instead, and the data section names no file (tmp is deleted once
    the fit returns) but holds the sequences."""
    def scrub(v):
        if isinstance(v, str):
            return v.replace(tmp, "the strain and stress given")
        if isinstance(v, list):
            return [scrub(e) for e in v]
        if isinstance(v, dict):
            return {k: scrub(e) for k, e in v.items()}
        return v
    result = scrub(result)
    data = result.get("data")
    if isinstance(data, dict):
        data["file"] = None
        data["source"] = "strain and stress sequences given to conifit.fit (stress in %s)" % \
            stress_unit
        data["strain"] = list(x)
        data["stress"] = list(y)
    return result


def _in_sequences(err, tmp, count):
    """err about the temporary table fit() wrote from strain and stress, told in their terms:
    "TMP:LINE:COLUMN: column '...': ..." (a value) names strain[i] or stress[i] (line 2 holds
    index 0), anything else both sequences; the temporary is never named (it is gone)."""
    msg = str(err)
    m = re.match(re.escape(tmp) + r":(\d+)(?::(\d+))?: ", msg)
    if m:
        i, col = int(m.group(1)) - 2, m.group(2)
        if 0 <= i < count and col in ("1", "2") and msg[m.end():].startswith("column '"):
            where = "%s[%d]" % ("strain" if col == "1" else "stress", i)
        else:
            where = "strain, stress"
        msg = where + ": " + msg[m.end():]
    msg = msg.replace(tmp, "the strain and stress given")
    out = Error(0, msg)
    out.status = err.status
    return out


def simulate(scene):
    """Runs the scene file and returns its samples as the columns of conifit simulate's CSV: a
    dict of array.array, one a column, the i-th sample at index i of each: time_s, strain,
    stress_kPa (compression positive), kinetic_energy_mJ, spring_stress_kPa, lateral_stretch (the
    lattice's width along x over its rest width; typecode 'd') and stable (typecode 'b': 1, 0, or
    -1 in explicit dynamics). 8 bytes a number (a scene's samples within the budget fit in memory
    as they do in the library)."""
    rows = ctypes.POINTER(ctypes.c_double)()
    count = ctypes.c_size_t()
    e = _CfError()
    _check(_lib.cf_flat_simulate(_text(scene, "scene"), ctypes.byref(rows), ctypes.byref(count),
                                 ctypes.byref(e)), e)
    try:
        w, n = len(_SAMPLE_KEYS), count.value
        flat = array.array("d")
        if n:
            flat.frombytes(ctypes.string_at(rows, n * w * ctypes.sizeof(ctypes.c_double)))
    finally:
        _lib.cf_flat_free(rows)
    out = {key: flat[j::w] for j, key in enumerate(_SAMPLE_KEYS)}
    out["stable"] = array.array("b", (int(v) for v in out["stable"]))
    return out


def export(fit_file, format, type=None, tol=0.0):
    """The spring of a fit file written for another simulator (format as conifit export
    --format: json, csv, calculix, abaqus, febio, lsdyna, sofa), as text."""
    out = ctypes.c_void_p()
    e = _CfError()
    tol = _number(tol, "tol")
    _check(_lib.cf_flat_export(_text(fit_file, "fit file"), _text(type, "type"),
                               _text(format, "format"), tol, ctypes.byref(out),
                               ctypes.byref(e)), e)
    return _taken(out)
