"""varia.lagrangian: a SymPy Lagrangian as a compiled Lagrangian plugin (docs/python.md).

The expression is printed once as C++, its common subexpressions shared (sympy.cse), into the
model function of an `sdk::AutodiffLagrangian<Model, n, n>`: the SDK differentiates that one
function exactly by forward-mode automatic differentiation, at every order and scalar the
constructions need, and reads a constant mass matrix off the model by itself. A symmetry is
given as generators A_k of a linear action on q (and v alike); the plugin declares it, with the
momentum map J_k = <dL/dv, A_k q>, so that `verify` predicts momentum conservation and measures
the invariance of L_d (a generator that is not a symmetry of L is reported as not holding). The source is
compiled against the SDK's headers into a plugin file cached by the hash of its text (and of the
compiler's command and of the SDK's and the ABI's headers), and the directory holding it is put on VARIA_PLUGIN_PATH, so that later
scenes of the process name the type.
"""

import hashlib
import json
import os
import shutil
import subprocess

import numpy as np
import sympy
from sympy.printing.c import C99CodePrinter

from . import _varia


class _Printer(C99CodePrinter):
    """C++ over the model's scalar T: q[i] -> q(i), v[i] -> v(i), parameters -> members; integer
    powers as products (no pow of an integer exponent at dual numbers), x**(1/2) as sqrt."""

    def __init__(self, names):
        super().__init__()
        self._names = names

    def _print_Symbol(self, symbol):
        return self._names.get(symbol, super()._print_Symbol(symbol))

    def _print_Pow(self, power):
        base, exponent = power.as_base_exp()
        if exponent.is_Integer and 0 < abs(int(exponent)) <= 8:
            product = "*".join(["(" + self._print(base) + ")"] * abs(int(exponent)))
            return "(" + product + ")" if exponent > 0 else "(1.0/(" + product + "))"
        if exponent == sympy.Rational(1, 2):
            return "sqrt(" + self._print(base) + ")"
        if exponent == sympy.Rational(-1, 2):
            return "(1.0/sqrt(" + self._print(base) + "))"
        return "pow(" + self._print(base) + ", T(" + self._print(sympy.Float(exponent)) + "))"


def _identifier(name):
    if not name or not all(c.isalnum() or c in "-_" for c in name) or not name[0].isalpha():
        raise ValueError(f"a Lagrangian's type name is letters, digits, '-' and '_', starting with a letter: {name!r}")
    return name.replace("-", "_")


def _generators(symmetry, n):
    """The symmetry as a list of n x n matrices A_k (floats): one matrix, or a list of them."""
    if symmetry is None:
        return []
    matrices = [symmetry] if np.asarray(symmetry, dtype=object).ndim == 2 else list(symmetry)
    generators = [np.array(sympy.Matrix(A).evalf(), dtype=float) for A in matrices]
    for A in generators:
        if A.shape != (n, n) or not np.all(np.isfinite(A)):
            raise ValueError(f"symmetry: each generator must be a finite {n} x {n} matrix")
    return generators


def _symmetry_source(generators, n):
    """The declared symmetry: the linear action q -> exp(sum_k t_k A_k) q (v alike), its momentum
    map J_k = <dL/dv, A_k q> (Noether), and the action of a group element drawn from a seed."""
    if not generators:
        return ""
    rows = ",\n      ".join("{" + ", ".join(repr(float(x)) for x in A.flatten()) + "}" for A in generators)
    return f"""
  const char* symmetry_group() const noexcept override {{ return "linear ({len(generators)} generator{'s' if len(generators) > 1 else ''}, varia.lagrangian)"; }}
  int momentum_size() const noexcept override {{ return {len(generators)}; }}
  varia::Status momentum(const double* q, const double* v, double* J) noexcept override {{
    double gradient[2 * {n}];
    if (const varia::Status failed = evaluate(q, v, nullptr, gradient, nullptr)) return failed;
    for (int k = 0; k < {len(generators)}; ++k) {{
      const Eigen::Map<const Eigen::Matrix<double, {n}, {n}, Eigen::RowMajor>> A(kGenerators[k]);
      J[k] = Eigen::Map<const Eigen::Matrix<double, {n}, 1>>(gradient + {n}).dot(A * Eigen::Map<const Eigen::Matrix<double, {n}, 1>>(q));
    }}
    return nullptr;
  }}
  varia::Status act(unsigned seed, const double* q, const double* v, double* gq, double* gv) noexcept override {{
    return varia::sdk::guarded(error_, [&] {{
      std::mt19937 engine(seed);
      std::uniform_real_distribution<double> angle(-1.0, 1.0);
      Eigen::Matrix<double, {n}, {n}> X = Eigen::Matrix<double, {n}, {n}>::Zero();
      for (int k = 0; k < {len(generators)}; ++k)
        X += angle(engine) * Eigen::Map<const Eigen::Matrix<double, {n}, {n}, Eigen::RowMajor>>(kGenerators[k]);
      const Eigen::Matrix<double, {n}, {n}> g = X.exp();
      const Eigen::Matrix<double, {n}, 1> x = g * Eigen::Matrix<double, {n}, 1>{{Eigen::Map<const Eigen::Matrix<double, {n}, 1>>{{q}}}};
      const Eigen::Matrix<double, {n}, 1> w = g * Eigen::Matrix<double, {n}, 1>{{Eigen::Map<const Eigen::Matrix<double, {n}, 1>>{{v}}}};
      Eigen::Map<Eigen::Matrix<double, {n}, 1>>{{gq}} = x;
      Eigen::Map<Eigen::Matrix<double, {n}, 1>>{{gv}} = w;
    }});
  }}

 private:
  static constexpr double kGenerators[{len(generators)}][{n * n}] = {{
      {rows}}};
"""


def _source(name, L, q, v, parameters, generators):
    n = len(q)
    names = {symbol: f"q({i})" for i, symbol in enumerate(q)}
    names.update({symbol: f"v({i})" for i, symbol in enumerate(v)})
    names.update({symbol: f"p_{k}_" for k, symbol in enumerate(parameters)})
    free = L.free_symbols - set(names)
    if free:
        raise ValueError("L has symbols that are neither q, v nor parameters: " + ", ".join(sorted(map(str, free))))
    printer = _Printer(names)
    common, (reduced,) = sympy.cse(L, symbols=sympy.numbered_symbols("x"))
    for symbol, _ in common:
        names[symbol] = str(symbol)
    body = "".join(f"    const T {symbol} = T({printer.doprint(value)});\n" for symbol, value in common)
    schema = {
        "$schema": "http://json-schema.org/draft-07/schema#",
        "type": "object",
        "properties": {str(s): {"type": "number", "default": float(d)} for s, d in parameters.items()},
        "additionalProperties": False,
    }
    members = "".join(f"  double p_{k}_;\n" for k in range(len(parameters)))
    reads = "".join(
        f",\n        p_{k}_(parameters.value({json.dumps(str(s))}, {float(d)!r}))" for k, (s, d) in enumerate(parameters.items()))
    properties = {"lagrangian": str(L), "generated": "varia.lagrangian (SymPy)", "manifold": f"Rn, dim {n}",
                  "symmetry": "linear, generators " + json.dumps([A.tolist() for A in generators]) if generators else "none"}
    return f"""// Generated by varia.lagrangian from a SymPy expression; do not edit.
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <unsupported/Eigen/MatrixFunctions>

#include "varia/sdk/autodiff_lagrangian.hpp"

namespace {{

class Generated final : public varia::sdk::AutodiffLagrangian<Generated, {n}, {n}> {{
 public:
  static constexpr const char* version = "1.0.0";
  static constexpr const char* parameter_schema = R"json({json.dumps(schema)})json";
  static constexpr const char* properties = R"json({json.dumps(properties)})json";

  Generated(const nlohmann::json& parameters, const varia::sdk::Context& context)
      : AutodiffLagrangian(){reads} {{
    if (context.manifold != "Rn" || context.dim != {n})
      throw std::invalid_argument("{name}: needs the manifold Rn with dim {n}, not " + context.manifold + " of dim " +
                                  std::to_string(context.dim));
  }}

  template <class T>
  T lagrangian(const varia::sdk::Vec<T>& q, const varia::sdk::Vec<T>& v) const {{
    using std::cos; using std::sin; using std::tan; using std::exp; using std::log; using std::sqrt; using std::pow;
    using std::atan; using std::cosh; using std::sinh; using std::tanh;
{body}    return {printer.doprint(reduced)};
  }}
{_symmetry_source(generators, n)}
 private:
{members}}};

}}  // namespace

VARIA_PLUGIN(Generated, lagrangian, {_identifier(name)})
"""


def _compile_command(source, target):
    return ["c++", "-std=c++20", "-O1", "-fPIC", "-shared", "-fvisibility=hidden", "-fvisibility-inlines-hidden",
            "-fno-math-errno", "-DBOOST_ALL_NO_LIB", "-DBOOST_DLL_USE_STD_FS",
            *[f"-I{d}" for d in _varia.sdk_include_dirs()], "-isystem", "/usr/include/eigen3",
            source, "-o", target]


def _headers_digest():
    """The SDK's and the ABI's headers, hashed: a plugin compiled against other headers (another
    ABI version, which the host refuses, or another SDK) is compiled again, not loaded from the cache."""
    digest = hashlib.sha256()
    for directory in _varia.sdk_include_dirs():
        for root, dirs, files in os.walk(directory):
            dirs.sort()
            for name in sorted(files):
                if name.endswith(".hpp"):
                    path = os.path.join(root, name)
                    digest.update(os.path.relpath(path, directory).encode() + b"\0")
                    with open(path, "rb") as f:
                        digest.update(f.read())
    return digest.digest()


_registered = {}  # type name -> the directory put on VARIA_PLUGIN_PATH for it


def _register(name, directory):
    entries = [p for p in os.environ.get("VARIA_PLUGIN_PATH", "").split(":") if p and p != _registered.get(name)]
    _registered[name] = directory
    os.environ["VARIA_PLUGIN_PATH"] = ":".join([directory, *entries])


def lagrangian(name, L, q, v, parameters=None, symmetry=None, directory=None):
    q, v = list(q), list(v)
    if len(q) != len(v) or not q:
        raise ValueError("q and v must be lists of the same positive length")
    parameters = dict(parameters or {})
    source = _source(name, sympy.sympify(L), q, v, parameters, _generators(symmetry, len(q)))
    cache = os.path.join(os.environ.get("XDG_CACHE_HOME", os.path.expanduser("~/.cache")), "varia", "lagrangians")
    key = hashlib.sha256((source + "\0" + " ".join(_compile_command("", ""))).encode() + _headers_digest()).hexdigest()[:24]
    where = os.path.join(cache, key)
    plugin = os.path.join(where, f"lagrangian_{_identifier(name)}.so")
    if not os.path.exists(plugin):
        os.makedirs(where, mode=0o700, exist_ok=True)
        os.chmod(cache, 0o700)
        with open(os.path.join(where, "model.cpp"), "w") as f:
            f.write(source)
        partial = plugin + ".partial"
        built = subprocess.run(_compile_command(os.path.join(where, "model.cpp"), partial), capture_output=True, text=True)
        if built.returncode != 0:
            raise RuntimeError(f"varia.lagrangian: compiling {name} failed:\n{built.stderr[-4000:]}")
        os.chmod(partial, 0o755)
        os.replace(partial, plugin)  # whole or absent: a concurrent process never loads half a file
    if directory is not None:
        os.makedirs(directory, exist_ok=True)
        shutil.copy2(plugin, os.path.join(directory, os.path.basename(plugin)))
    _register(name, where)
    return plugin
