"""robocfg's own instructions an episode, by Python function (callgrind), PyBullet's and pinocchio's
calls excluded.

    python benchmarks/bench_own_instructions.py [--task pick_place] [--episodes 3] [--top 25]

Needs valgrind, gcc and Python's headers. CPython 3.11 shows callgrind only its interpreter's C
functions, so the script builds a small C extension with two C functions per wrapped Python
function: ``rc_<i>_<name>`` (calls it: its inclusive cost is the function's, callees included) and
``via_<i>_<name>`` (every wrapped call made while function i is the innermost wrapped one goes
through it: its inclusive cost is what i's callees cost). Wrapped: every plain function and method
defined in ``robocfg`` (found in the loaded modules' and classes' namespaces; nested functions,
lambdas, properties, static and class methods are not, and count as their caller's own work),
and every callable of the ``pybullet`` and ``pinocchio`` modules. A function's own instructions =
inclusive − its callees' (wrapped) calls: its body, the numpy it calls, the interpreter's work on
its behalf; the pybullet/pinocchio rows are the libraries' work (not own). The wrappers add a few
hundred instructions a call to the caller's own count (the Python-side call of the wrapper).

In a child under ``valgrind --tool=callgrind --instr-atstart=no``: a session of ``--task``,
episode 0 as a warm-up, then instrumentation on around episodes 1 .. ``--episodes`` and a dump.
The parent reads the dump's inclusive costs of the ``rc_``/``via_`` functions (callgrind_annotate
--inclusive=yes) and prints instructions an episode. Instruction counts do not move with the load.
"""

from __future__ import annotations

import argparse
import importlib
import inspect
import os
import re
import shutil
import subprocess
import sys
import sysconfig
import tempfile
import types
from pathlib import Path

HERE = Path(__file__).resolve().parent

C_HEAD = """
#include <Python.h>
static PyObject *targets[%(n)d];
static int stack[65536];
static int depth = 0;
typedef PyObject *(*callfn)(PyObject *, PyObject *);
typedef PyObject *(*viafn)(int, PyObject *, PyObject *);
static callfn calls[%(n)d];
static viafn vias[%(n)d];
"""

C_FN = """
__attribute__((noinline)) static PyObject *rc_%(i)d_%(name)s(PyObject *a, PyObject *k) {
    stack[depth++] = %(i)d;
    PyObject *r = PyObject_Call(targets[%(i)d], a, k);
    depth--;
    return r;
}
__attribute__((noinline)) static PyObject *via_%(i)d_%(name)s(int j, PyObject *a, PyObject *k) {
    PyObject *r = calls[j](a, k);
    return r;
}
"""

C_TAIL = """
static PyObject *entry(PyObject *self, PyObject *a, PyObject *k) {
    int j = (int)PyLong_AsLong(self);
    if (depth > 0) return vias[stack[depth - 1]](j, a, k);
    return calls[j](a, k);
}
static PyMethodDef entry_def = {"entry", (PyCFunction)(void (*)(void))entry, METH_VARARGS | METH_KEYWORDS, NULL};
static PyObject *make(PyObject *self, PyObject *args) {
    int i; PyObject *f;
    if (!PyArg_ParseTuple(args, "iO", &i, &f)) return NULL;
    Py_INCREF(f); targets[i] = f;
    PyObject *idx = PyLong_FromLong(i);
    PyObject *c = PyCFunction_New(&entry_def, idx);
    Py_DECREF(idx);
    return c;
}
static PyMethodDef methods[] = {{"make", make, METH_VARARGS, NULL}, {NULL, NULL, 0, NULL}};
static struct PyModuleDef mod = {PyModuleDef_HEAD_INIT, "cgtramp", NULL, -1, methods};
PyMODINIT_FUNC PyInit_cgtramp(void) {
%(init)s
    return PyModule_Create(&mod);
}
"""


def _targets() -> list[tuple[object, str, object, str]]:
    """(holder, attribute, function, name) of everything to wrap, one entry per holder attribute."""
    out = []
    for modname, mod in sorted(sys.modules.items()):
        if mod is None or not (modname == "robocfg" or modname.startswith("robocfg.")):
            continue
        for attr, v in list(vars(mod).items()):
            if isinstance(v, types.FunctionType) and v.__module__.startswith("robocfg") and "<" not in v.__qualname__:
                out.append((mod, attr, v, f"{v.__module__}.{v.__qualname__}"))
            elif inspect.isclass(v) and v.__module__ == modname:
                for cattr, cv in list(vars(v).items()):
                    if isinstance(cv, types.FunctionType) and cv.__module__.startswith("robocfg") \
                            and "<" not in cv.__qualname__:
                        out.append((v, cattr, cv, f"{cv.__module__}.{cv.__qualname__}"))
    for libname in ("pybullet", "pinocchio"):
        lib = sys.modules.get(libname)
        if lib is None:
            continue
        for attr, v in list(vars(lib).items()):
            if isinstance(v, types.BuiltinFunctionType) or (isinstance(v, types.FunctionType) and libname == "pinocchio"):
                out.append((lib, attr, v, f"{libname}.{attr}"))
    return out


def _build(names: list[str], tmp: Path):
    safe = [re.sub(r"\W", "_", n)[-80:] for n in names]
    init = "\n".join(f"    calls[{i}] = rc_{i}_{s}; vias[{i}] = via_{i}_{s};" for i, s in enumerate(safe))
    src = C_HEAD % {"n": len(names)} + "".join(C_FN % {"i": i, "name": s} for i, s in enumerate(safe)) \
        + C_TAIL % {"init": init}
    c = tmp / "cgtramp.c"
    c.write_text(src)
    so = tmp / ("cgtramp" + sysconfig.get_config_var("EXT_SUFFIX"))
    subprocess.run(["gcc", "-O1", "-fno-ipa-icf", "-fno-inline", "-g", "-shared", "-fPIC",
                    f"-I{sysconfig.get_paths()['include']}", str(c), "-o", str(so)], check=True)
    sys.path.insert(0, str(tmp))
    return importlib.import_module("cgtramp")


def child(task_name: str, episodes: int, seed: int, tmp: Path) -> None:
    sys.path.insert(0, str(HERE))
    from bench_control_swap import _task

    from robocfg.sim.quiet import quiet_import

    quiet_import()
    import pinocchio  # noqa: F401
    import pybullet  # noqa: F401

    from robocfg.engine import RunOptions, open_session

    with open_session(_task(task_name), RunOptions(seed=seed)) as session:
        session.run(0)  # imports, caches
        targets = _targets()
        funcs: dict[int, int] = {}
        names: list[str] = []
        for _, _, f, name in targets:
            if id(f) not in funcs:
                funcs[id(f)] = len(names)
                names.append(name)
        tramp = _build(names, tmp)
        made = {}
        for holder, attr, f, _ in targets:
            i = funcs[id(f)]
            if i not in made:
                made[i] = tramp.make(i, f)
            w = made[i]
            if inspect.isclass(holder):
                w = _instancemethod(w)
            setattr(holder, attr, w)
        session.run(0)  # the wrappers' own first use
        pid = str(os.getpid())
        subprocess.run(["callgrind_control", "-i", "on", pid], check=True, capture_output=True)
        for k in range(1, episodes + 1):
            rec = session.run(k)
            print(f"episode {k}: {getattr(rec, 'success', '?')}, {getattr(rec, 'steps', '?')} steps", flush=True)
        subprocess.run(["callgrind_control", "-d", "episodes", pid], check=True, capture_output=True)
        subprocess.run(["callgrind_control", "-i", "off", pid], check=True, capture_output=True)


def _instancemethod(f):
    """``f`` (a builtin) bound like a function when looked up on an instance (C's PyInstanceMethod)."""
    import ctypes

    new = ctypes.pythonapi.PyInstanceMethod_New
    new.restype, new.argtypes = ctypes.py_object, [ctypes.py_object]
    return new(f)


def inclusive(dump: Path) -> dict[str, int]:
    """Inclusive instructions of the ``rc_``/``via_`` functions in a callgrind dump."""
    p = subprocess.run(["callgrind_annotate", "--inclusive=yes", "--threshold=100", str(dump)],
                       capture_output=True, text=True, check=True)
    out: dict[str, int] = {}
    for line in p.stdout.splitlines():
        m = re.match(r"^\s*([\d,]+)\s+(?:\([^)]*\)\s+)?\S*:(rc|via)_(\d+)_\w+", line)
        if m:
            out[f"{m.group(2)}_{m.group(3)}"] = out.get(f"{m.group(2)}_{m.group(3)}", 0) + int(m.group(1).replace(",", ""))
    return out


def call_counts(dump: Path) -> dict[int, int]:
    """Calls of each ``rc_<i>`` function in a callgrind dump (its ``calls=`` lines), by i."""
    names: dict[str, str] = {}
    out: dict[int, int] = {}
    target = None
    for line in dump.read_text(errors="replace").splitlines():
        m = re.match(r"^c?fn=\((\d+)\)(?: (.*))?$", line)
        if m:
            if m.group(2):
                names[m.group(1)] = m.group(2)
            target = names.get(m.group(1), "") if line.startswith("cfn=") else None
            continue
        if line.startswith("calls=") and target:
            r = re.match(r"rc_(\d+)_", target)
            if r:
                out[int(r.group(1))] = out.get(int(r.group(1)), 0) + int(line[6:].split()[0])
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--task", default="pick_place")
    ap.add_argument("--episodes", type=int, default=3)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--top", type=int, default=25)
    ap.add_argument("--keep", type=Path, help="keep the dump and the names here")
    ap.add_argument("--child", type=Path, help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.child is not None:
        child(a.task, a.episodes, a.seed, a.child)
        return 0
    if shutil.which("valgrind") is None or shutil.which("gcc") is None:
        print("valgrind and gcc are needed: nothing counted")
        return 2
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        out = tmp / "cg.out"
        cmd = ["valgrind", "--tool=callgrind", "--instr-atstart=no", f"--callgrind-out-file={out}",
               sys.executable, __file__, "--task", a.task, "--episodes", str(a.episodes), "--seed", str(a.seed),
               "--child", str(tmp)]
        p = subprocess.run(cmd, capture_output=True, text=True)
        print("\n".join(line for line in p.stdout.splitlines() if line.strip()))
        if p.returncode != 0:
            print(p.stderr[-3000:])
            return 1
        dump = next(f for f in sorted(tmp.glob("cg.out*")) if f.name != "cg.out")
        names = {}
        for m in re.finditer(r"calls\[(\d+)\] = rc_\d+_(\w+);", (tmp / "cgtramp.c").read_text()):
            names[int(m.group(1))] = m.group(2)
        cost, ncalls = inclusive(dump), call_counts(dump)
        if a.keep is not None:
            a.keep.mkdir(parents=True, exist_ok=True)
            shutil.copy(dump, a.keep / "callgrind.out")
            shutil.copy(tmp / "cgtramp.c", a.keep / "cgtramp.c")
    rows = []
    for i, name in names.items():
        inc = cost.get(f"rc_{i}", 0)
        if not inc:
            continue
        callees = cost.get(f"via_{i}", 0)
        lib = name.startswith(("pybullet_", "pinocchio_"))
        rows.append((name, inc / a.episodes, (inc - callees) / a.episodes, lib, ncalls.get(i, 0) / a.episodes))
    own_total = sum(r[2] for r in rows if not r[3])
    print(f"{a.task}, episodes 1..{a.episodes} (callgrind): robocfg's own instructions "
          f"{own_total / 1e6:.2f} M an episode (wrapped functions' own work; the libraries' calls excluded)")
    print(f"{'function':70s} {'own M/ep':>9s} {'incl M/ep':>10s} {'calls/ep':>9s}")
    for name, inc, own, _, n in sorted((r for r in rows if not r[3]), key=lambda r: -r[2])[: a.top]:
        print(f"{name:70s} {own / 1e6:9.3f} {inc / 1e6:10.3f} {n:9.1f}")
    print("libraries (inclusive M an episode):")
    for name, inc, _, _, n in sorted((r for r in rows if r[3]), key=lambda r: -r[1])[:10]:
        print(f"{name:70s} {'':9s} {inc / 1e6:10.3f} {n:9.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
