"""varia.lagrangian (docs/python.md): a SymPy Lagrangian compiled into a plugin. The double
pendulum written in SymPy takes the bundled double-pendulum's steps; the Henon-Heiles system with
Galerkin degree 1 and the trapezoid rule is explicit (its constant mass matrix detected: no
Newton iteration) and is a hand-written Stormer-Verlet's. Compiled into a cache of the test's own,
so the first call compiles (the time is printed, not asserted) and the second finds it."""

import os
import tempfile
import time
import unittest

import numpy as np
import sympy as sp

import varia


class LagrangianTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.cache = tempfile.TemporaryDirectory()
        os.environ["XDG_CACHE_HOME"] = cls.cache.name

    @classmethod
    def tearDownClass(cls):
        cls.cache.cleanup()

    def test_a_sympy_double_pendulum_takes_the_bundled_double_pendulums_steps(self):
        q1, q2, v1, v2, m1, m2, l1, l2, g = sp.symbols("q1 q2 v1 v2 m1 m2 l1 l2 g")
        L = ((m1 + m2) / 2 * l1**2 * v1**2 + m2 / 2 * l2**2 * v2**2 + m2 * l1 * l2 * v1 * v2 * sp.cos(q1 - q2)
             + (m1 + m2) * g * l1 * sp.cos(q1) + m2 * g * l2 * sp.cos(q2))
        parameters = {m1: 1, m2: 0.5, l1: 1, l2: 0.7, g: 9.81}
        start = time.monotonic()
        plugin = varia.lagrangian("sympy-double-pendulum", L, [q1, q2], [v1, v2], parameters)
        compiled = time.monotonic() - start
        start = time.monotonic()
        self.assertEqual(varia.lagrangian("sympy-double-pendulum", L, [q1, q2], [v1, v2], parameters), plugin)
        print(f"\ncompiled in {compiled:.1f} s, found in the cache in {time.monotonic() - start:.3f} s")
        scene = {"system": {"manifold": {"type": "Rn", "dim": 2},
                            "lagrangian": {"type": "double-pendulum", "mass2": 0.5, "length2": 0.7, "gravity": 9.81}},
                 "method": {"construction": "galerkin", "degree": 2, "quadrature": {"type": "gauss-lobatto", "points": 3}},
                 "initial": {"q": [1.0, 0.5], "v": [0.0, 0.3]}, "step": 0.01, "steps": 2000}
        bundled = varia.run(scene)
        scene["system"]["lagrangian"] = {"type": "sympy-double-pendulum"}
        generated = varia.run(scene)
        difference = max(np.abs(bundled.q - generated.q).max(), np.abs(bundled.p - generated.p).max())
        print(f"largest difference from the bundled double-pendulum over 2000 steps: {difference:.3g}")
        self.assertLessEqual(difference, 1e-11)

    def test_henon_heiles_with_the_trapezoid_rule_is_explicit_stormer_verlet(self):
        q1, q2, v1, v2 = sp.symbols("q1 q2 v1 v2")
        L = (v1**2 + v2**2) / 2 - (q1**2 + q2**2) / 2 - q1**2 * q2 + q2**3 / 3
        varia.lagrangian("sympy-henon-heiles", L, [q1, q2], [v1, v2])
        h, steps, q, p = 0.05, 400, np.array([0.1, -0.2]), np.array([0.3, 0.15])
        run = varia.run({"system": {"manifold": {"type": "Rn", "dim": 2}, "lagrangian": {"type": "sympy-henon-heiles"}},
                         "method": {"construction": "galerkin", "degree": 1, "quadrature": {"type": "trapezoid"}},
                         "initial": {"q": list(q), "p": list(p)}, "step": h, "steps": steps})
        self.assertEqual(run.record["newton_iterations"]["max"], 0)

        def force(x):
            return np.array([-x[0] - 2 * x[0] * x[1], -x[1] - x[0] ** 2 + x[1] ** 2])

        for _ in range(steps):  # Stormer-Verlet, written here
            half = p + h / 2 * force(q)
            q = q + h * half
            p = half + h / 2 * force(q)
        self.assertLessEqual(np.abs(run.q[-1] - q).max(), 1e-13)
        self.assertLessEqual(np.abs(run.p[-1] - p).max(), 1e-13)

    def test_a_declared_rotation_is_verified_and_a_false_symmetry_is_reported_as_not_holding(self):
        x, y, u, w = sp.symbols("x y u w")
        L = (u**2 + w**2) / 2 - (x**2 + y**2) ** 2 / 4  # an isotropic quartic well: rotations about the origin
        scene = {"system": {"manifold": {"type": "Rn", "dim": 2}, "lagrangian": {"type": "sympy-quartic"}},
                 "method": {"construction": "galerkin", "degree": 2, "quadrature": {"type": "gauss-lobatto", "points": 3}},
                 "initial": {"q": [1.0, 0.0], "v": [0.0, 0.8]}, "step": 0.05, "steps": 200, "observe": ["momentum"]}
        varia.lagrangian("sympy-quartic", L, [x, y], [u, w], symmetry=[[0, -1], [1, 0]])
        checks = {c["name"]: c for c in varia.verify(scene)["checks"]}
        for name in ("g_invariant", "momentum_conserved"):
            self.assertTrue(checks[name]["predicted"], name)
            self.assertTrue(checks[name]["holds"], name)
        run = varia.run(scene)
        self.assertLessEqual(np.abs(run.observables["momentum0"] - 0.8).max(), 1e-13)  # J = x w - y u
        varia.lagrangian("sympy-quartic", L, [x, y], [u, w], symmetry=[[1, 0], [0, -1]])  # a squeeze: no symmetry
        checks = {c["name"]: c for c in varia.verify(scene)["checks"]}
        self.assertTrue(checks["g_invariant"]["predicted"])
        self.assertFalse(checks["g_invariant"]["holds"])

    def test_the_spherical_pendulum_in_angles_warns_through_the_pole_region_and_on_a_rod_it_does_not(self):
        # Issue #40 item 5: in the angles (theta from the upward vertical, phi), a small azimuthal
        # velocity swings the bob near the lower pole, where phi' = p_phi / sin^2 theta is large;
        # the same motion as a point on a rod has no such chart.
        theta, phi, u, w = sp.symbols("theta phi u w")
        L = (u**2 + sp.sin(theta) ** 2 * w**2) / 2 - 9.81 * sp.cos(theta)
        varia.lagrangian("spherical-pendulum-angles", L, [theta, phi], [u, w])
        method = {"construction": "galerkin", "degree": 1, "quadrature": {"type": "gauss-lobatto", "points": 2}}
        angles = varia.run({"system": {"manifold": {"type": "Rn", "dim": 2}, "lagrangian": {"type": "spherical-pendulum-angles"}},
                            "method": method, "initial": {"q": [1.0, 0.0], "v": [0.0, 0.3]}, "step": 0.002, "steps": 5000,
                            "observe": ["energy"]})
        self.assertEqual(len(angles.record["warnings"]), 1)
        self.assertIn("the energy departed", angles.record["warnings"][0])
        rod = varia.run({"system": {"manifold": {"type": "Rn", "dim": 3},
                                    "lagrangian": {"type": "composite", "space_dim": 3, "masses": [1],
                                                   "terms": [{"type": "gravity", "g": [0, 0, -9.81]}]},
                                    "constraints": [{"type": "rod", "anchor": [0, 0, 0], "particle": 0}]},
                         "method": method, "step": 0.002, "steps": 5000, "observe": ["energy"],
                         "initial": {"q": [np.sin(1.0), 0.0, np.cos(1.0)], "v": [0.0, 0.3 * np.sin(1.0), 0.0]}})
        self.assertNotIn("warnings", rod.record)
        print(f"\nenergy error: in angles {angles.record['energy_error_max']:.3g}, on a rod {rod.record['energy_error_max']:.3g}")
        self.assertLess(rod.record["energy_error_max"], angles.record["energy_error_max"] / 100)

    def test_symbols_that_are_not_q_v_or_parameters_are_refused(self):
        x, v, k = sp.symbols("x v k")
        with self.assertRaises(ValueError):
            varia.lagrangian("sympy-unknown", v**2 / 2 - k * x**2 / 2, [x], [v])


if __name__ == "__main__":
    unittest.main()
