"""Gauss steps at round-off (issue #43, item 6): the Galerkin construction of degree s with s
Gauss points is the s-stage Gauss method, and its steps on the outer solar system
(scenes/effects/outer-solar-system.json: days, AU and solar masses, planets of 1e-3 to 1e-8 of
the Sun's mass) must end where the exact method's do, to round-off. The reference is the same
method in 60 digits (mpmath): the Nystrom form of the s-stage Gauss collocation, iterated to
1e-55. Hairer's gni_irk2 (s = 6) ends 5.7e-15 from it after 30 steps of 100 days; varia ended
3.3e-13 from it before the node iteration took composite systems and measured its residual in
velocity units (docs/effects.md)."""

import json
import unittest

import mpmath as mp

import varia

SCENE = "scenes/effects/outer-solar-system.json"


def gauss_coefficients(s):
    """Nodes c, weights b and the Nystrom matrix A^2 of the s-stage Gauss collocation."""
    roots = mp.polyroots(mp.taylor(lambda x: mp.legendre(s, x), 0, s)[::-1], maxsteps=200, extraprec=200)
    c = sorted((1 + mp.re(r)) / 2 for r in roots)

    def integral_of_basis(j, upper):
        return mp.quad(lambda t: mp.fprod((t - c[k]) / (c[j] - c[k]) for k in range(s) if k != j), [0, upper])

    A = [[integral_of_basis(j, c[i]) for j in range(s)] for i in range(s)]
    b = [integral_of_basis(j, 1) for j in range(s)]
    A2 = [[mp.fsum(A[i][k] * A[k][j] for k in range(s)) for j in range(s)] for i in range(s)]
    return c, b, A2


def gauss_reference(scene, s, h, steps):
    """q and v after `steps` steps of the s-stage Gauss method on Newton's N-body problem."""
    lagrangian = scene["system"]["lagrangian"]
    m = [mp.mpf(repr(x)) for x in lagrangian["masses"]]
    G = mp.mpf(repr(lagrangian["terms"][0]["G"]))
    q = [mp.mpf(repr(x)) for x in scene["initial"]["q"]]
    v = [mp.mpf(repr(x)) for x in scene["initial"]["v"]]
    n, bodies = len(q), len(m)
    c, b, A2 = gauss_coefficients(s)

    def acceleration(x):
        a = [mp.mpf(0)] * n
        for i in range(bodies):
            for j in range(bodies):
                if i != j:
                    d = [x[3 * j + k] - x[3 * i + k] for k in range(3)]
                    r3 = mp.fsum(e * e for e in d) ** mp.mpf(1.5)
                    for k in range(3):
                        a[3 * i + k] += G * m[j] * d[k] / r3
        return a

    for _ in range(steps):
        F = [acceleration(q)] * s
        for _ in range(100):
            stages = [[q[k] + c[i] * h * v[k] + h * h * mp.fsum(A2[i][j] * F[j][k] for j in range(s)) for k in range(n)]
                      for i in range(s)]
            new = [acceleration(stage) for stage in stages]
            change = max(abs(new[i][k] - F[i][k]) for i in range(s) for k in range(n))
            F = new
            if change < mp.mpf(10) ** -55:
                break
        q = [q[k] + h * v[k] + h * h * mp.fsum(b[i] * (1 - c[i]) * F[i][k] for i in range(s)) for k in range(n)]
        v = [v[k] + h * mp.fsum(b[i] * F[i][k] for i in range(s)) for k in range(n)]
    return q, v


class GaussRoundOffTest(unittest.TestCase):
    def test_six_stage_gauss_on_the_outer_solar_system_ends_at_round_off(self):
        mp.mp.dps = 60
        with open(SCENE) as f:
            scene = json.load(f)
        s, h, steps = 6, 100, 30
        scene["method"] = {"construction": "galerkin", "degree": s, "quadrature": {"type": "gauss-legendre", "points": s}}
        scene["t_end"] = h * steps
        q_ref, v_ref = gauss_reference(scene, s, mp.mpf(h), steps)
        run = varia.run(scene)
        masses = scene["system"]["lagrangian"]["masses"]
        q_error = max(abs(mp.mpf(float(x)) - r) for x, r in zip(run.q[-1], q_ref))
        v_error = max(abs(mp.mpf(float(p)) / mp.mpf(repr(masses[k // 3])) - r)
                      for k, (p, r) in enumerate(zip(run.p[-1], v_ref)))
        # |q| is up to 30 AU, where an ulp is 3.6e-15; velocities are 1e-3 to 6e-3 AU a day
        self.assertLessEqual(q_error, 3e-14, "positions %.3g from the exact Gauss steps" % q_error)
        self.assertLessEqual(v_error, 3e-17, "velocities %.3g from the exact Gauss steps" % v_error)


if __name__ == "__main__":
    unittest.main()
