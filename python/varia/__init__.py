"""varia from Python: the commands of the `varia` program as functions (docs/python.md).

A scene is a dict, a JSON text or the path of a scene file. Every function runs on the same core
and the same code as the CLI: `run` returns the numbers the CLI writes, to the bit.

    import varia
    run = varia.run("scenes/default.json")
    run.t, run.q, run.p            # numpy arrays: rows, rows x N, rows x M
    run.observables["energy"]      # one array per observable column
    run.record["newton_iterations"]
"""

import json
import os
import tempfile

import numpy as np

from . import _varia

__all__ = ["SceneError", "NumericalFailure", "PluginFault", "Run", "plugins", "validate", "run", "verify", "ld",
           "cost", "lagrangian"]


class SceneError(Exception):
    """A scene the CLI refuses with exit 2: `pointer` is the JSON pointer at fault ("/step"), or
    "" where the message names no place in the scene; `message` the CLI's message."""

    def __init__(self, pointer, message):
        super().__init__(message)
        self.pointer = pointer
        self.message = message


class NumericalFailure(Exception):
    """A step that failed (the CLI's exit 4): `step` and `t` (the time it started from; None
    where no step was being taken), `residual`, and `run`: the rows so far, as a Run."""

    def __init__(self, message, step=None, t=None, residual=None, run=None):
        super().__init__(message)
        self.step, self.t, self.residual, self.run = step, t, residual, run


class PluginFault(Exception):
    """A plugin that failed (the CLI's exit 3): `file` is the plugin file."""

    def __init__(self, message, file):
        super().__init__(message)
        self.file = file


class Run:
    """A trajectory: `t` (rows), `q` (rows x N), `p` (rows x M), `observables` (name -> array,
    as the CSV's columns), `record` (the run record, as `--summary` writes it)."""

    def __init__(self, arrays, record):
        self.t, self.q, self.p = arrays["t"], arrays["q"], arrays["p"]
        self.observables = {name: arrays["observables"][:, k] for k, name in enumerate(arrays["columns"])}
        self.record = record

    def __repr__(self):
        return f"Run({len(self.t)} rows, q {self.q.shape[1]}, p {self.p.shape[1]}, observables {list(self.observables)})"


def _scene(scene):
    """(kind, value) for the extension: a dict as JSON text, a path as a path, else JSON text."""
    if isinstance(scene, dict):
        return "text", json.dumps(scene)
    if isinstance(scene, os.PathLike) or (isinstance(scene, str) and not scene.lstrip().startswith("{")):
        return "path", os.fspath(scene)
    if isinstance(scene, str):
        return "text", scene
    raise TypeError("a scene is a dict, a JSON text or a path, not " + type(scene).__name__)


def _call(function, *arguments):
    try:
        return function(*arguments)
    except _varia.Failure as failure:
        what = json.loads(str(failure))
        if what["kind"] == "scene":
            raise SceneError(what["pointer"], what["message"]) from None
        if what["kind"] == "plugin":
            raise PluginFault(what["message"], what["file"]) from None
        if what["kind"] == "numerical":
            raise NumericalFailure(what["message"], residual=what["residual"]) from None
        raise RuntimeError(what["message"]) from None


def plugins():
    """The plugins found, as `varia plugins --json` lists them: a list of dicts."""
    return json.loads(_call(_varia.plugins))


def validate(scene):
    """Checks and assembles a scene as `varia validate` does; raises SceneError where it exits 2."""
    _call(_varia.validate, *_scene(scene))


def run(scene):
    """Runs a scene as `varia run` does and returns its Run; raises NumericalFailure (with the
    rows so far) where the CLI exits 4."""
    result = _call(_varia.run, *_scene(scene))
    trajectory = Run(result, json.loads(result["record"]))
    if result["failure"]:
        failure = json.loads(result["failure"])
        raise NumericalFailure(failure["message"], failure["step"], failure["t"], failure["residual"], trajectory)
    return trajectory


def verify(scene, h=None):
    """The checks of `varia verify` (the dict `verify --json` writes); `h`: the step sizes of the
    order fits, as `--h` gives them."""
    return json.loads(_call(_varia.verify, *_scene(scene), [float(x) for x in (h or [])]))


def ld(scene, q0, q1, h):
    """{"Ld", "D1", "D2"} of the scene's discrete Lagrangian, as `varia ld --json` prints them."""
    values = [float(x) for x in np.ravel(q0)], [float(x) for x in np.ravel(q1)]
    return json.loads(_call(_varia.ld, *_scene(scene), *values, float(h)))


def cost(scenes, h=None):
    """What accuracy costs, as `varia cost` measures it: the dict of its cost.json (per method:
    the predicted order, the fitted slope, the rows of the sweep, the reference used). `scenes`:
    a list of scenes (dicts, JSON texts or paths); `h`: the step sizes, as `--h`."""
    with tempfile.TemporaryDirectory() as directory:
        files = []
        for k, scene in enumerate(scenes):
            kind, value = _scene(scene)
            if kind == "path":
                files.append(value)
                continue
            files.append(os.path.join(directory, f"scene{k}.json"))  # a method's name: the scene's "name", else this stem
            with open(files[-1], "w") as f:
                f.write(value)
        out = os.path.join(directory, "out")
        os.mkdir(out)
        _call(_varia.cost, files, [float(x) for x in (h or [])], out)
        with open(os.path.join(out, "cost.json")) as f:
            return json.load(f)


def lagrangian(name, L, q, v, parameters=None, symmetry=None, directory=None):
    """Makes the SymPy expression L in the symbols q and v (lists) and in `parameters` (a dict:
    symbol -> default) a Lagrangian plugin of type `name` on Rn with dim len(q), usable by the
    process's later scenes; `directory` also receives its file (for --plugin-path). Its
    derivatives are exact (the SDK's automatic differentiation of the generated model), a constant
    mass matrix is detected; the file is compiled once and cached by the expression's hash.
    `symmetry`: a generator A (an n x n matrix) of a linear action q -> exp(t A) q, v alike, or a
    list of them; the plugin declares it with the momentum map J = <dL/dv, A q>. Returns the
    plugin file. (varia/codegen.py)"""
    from .codegen import lagrangian as generate  # SymPy is imported only here

    return generate(name, L, q, v, parameters, symmetry, directory)
