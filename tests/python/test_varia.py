"""The Python module against the CLI (docs/python.md): the same numbers to the bit, the same
errors as exceptions with what the CLI's messages carry. Run by ctest with PYTHONPATH set to the
build's python directory and VARIA_BUILD_DIR, from the source directory."""

import csv
import json
import os
import subprocess
import tempfile
import unittest

import numpy as np

import varia

BUILD = os.environ["VARIA_BUILD_DIR"]
VARIA = os.path.join(BUILD, "bin", "varia")


def cli(*arguments):
    return subprocess.run([VARIA, *arguments], capture_output=True, text=True, check=False)


class RunTest(unittest.TestCase):
    def test_run_equals_the_cli_csv_to_the_bit(self):
        with tempfile.TemporaryDirectory() as directory:
            out = os.path.join(directory, "t.csv")
            self.assertEqual(cli("run", "scenes/default.json", "--quiet", "--out", out).returncode, 0)
            with open(out, newline="") as f:
                rows = list(csv.reader(f))
        header, values = rows[0], np.array([[float(x) for x in row] for row in rows[1:]])
        run = varia.run("scenes/default.json")
        self.assertEqual(header, ["t", "q0", "p0", "energy"])
        self.assertTrue(np.array_equal(run.t, values[:, 0]))
        self.assertTrue(np.array_equal(run.q[:, 0], values[:, 1]))
        self.assertTrue(np.array_equal(run.p[:, 0], values[:, 2]))
        self.assertTrue(np.array_equal(run.observables["energy"], values[:, 3]))
        self.assertEqual(run.record["steps"], len(values) - 1)

    def test_a_scene_as_a_dict_or_text_runs_as_the_file(self):
        with open("scenes/default.json") as f:
            text = f.read()
        from_file, from_dict, from_text = varia.run("scenes/default.json"), varia.run(json.loads(text)), varia.run(text)
        self.assertTrue(np.array_equal(from_file.q, from_dict.q))
        self.assertTrue(np.array_equal(from_file.p, from_text.p))

    def test_constraint_observables_are_columns(self):
        run = varia.run("scenes/multibody/spherical-pendulum-rod-s2.json")
        self.assertEqual(list(run.observables), ["energy", "constraint", "constraint_velocity"])
        self.assertLessEqual(run.observables["constraint"].max(), 1e-14)
        self.assertEqual(run.record["constraint_error_max"], run.observables["constraint"].max())


class ErrorTest(unittest.TestCase):
    def test_scene_error_carries_the_pointer(self):
        with open("scenes/default.json") as f:
            scene = json.load(f)
        scene["step"] = -0.1
        with self.assertRaises(varia.SceneError) as raised:
            varia.validate(scene)
        self.assertEqual(raised.exception.pointer, "/step")
        self.assertIn("expected a number > 0", raised.exception.message)
        self.assertEqual(cli("validate", "scenes/bad/negative-step.json").returncode, 2)

    def test_a_failed_step_carries_the_step_and_the_rows_so_far(self):
        with self.assertRaises(varia.NumericalFailure) as raised:
            varia.run("scenes/hard/newton-fails.json")
        failure = raised.exception
        self.assertEqual(failure.step, 1)
        self.assertEqual(failure.t, 0.0)
        self.assertEqual(len(failure.run.t), failure.step)
        self.assertEqual(failure.run.record["failure"]["step"], failure.step)
        self.assertEqual(cli("run", "scenes/hard/newton-fails.json", "--quiet").returncode, 4)

    def test_a_plugin_fault_names_the_file(self):
        os.environ["VARIA_PLUGIN_PATH"] = os.path.join(BUILD, "tests", "fault_plugins")
        try:
            with open("scenes/default.json") as f:
                scene = json.load(f)
            scene["system"]["lagrangian"] = {"type": "fault-evaluate"}
            with self.assertRaises(varia.PluginFault) as raised:
                varia.run(scene)
            self.assertTrue(raised.exception.file.endswith("fault_throws_on_evaluation.so"))
            self.assertIn("deliberate failure in evaluate", str(raised.exception))
        finally:
            del os.environ["VARIA_PLUGIN_PATH"]


class CommandsTest(unittest.TestCase):
    def test_plugins_is_the_cli_list(self):
        listed = cli("plugins", "--json")
        self.assertEqual(varia.plugins(), json.loads(listed.stdout))

    def test_ld_is_the_cli_ld(self):
        printed = cli("ld", "scenes/default.json", "--q0", "0.1", "--q1", "0.2", "--h", "0.1", "--json")
        self.assertEqual(varia.ld("scenes/default.json", [0.1], [0.2], 0.1), json.loads(printed.stdout))

    def test_verify_is_the_cli_verify(self):
        scene = "scenes/multibody/spherical-pendulum-rod-s2.json"
        with tempfile.TemporaryDirectory() as directory:
            out = os.path.join(directory, "checks.json")
            self.assertEqual(cli("verify", scene, "--json", out).returncode, 0)
            with open(out) as f:
                expected = json.load(f)
        self.assertEqual(varia.verify(scene), expected)


def rotation(axis):
    """exp(hat(axis)), Rodrigues' formula."""
    angle = np.linalg.norm(axis)
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]]) / angle
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def rotation_log(R):
    """log(R) as a vector (R near the identity)."""
    angle = np.arccos(np.clip((np.trace(R) - 1) / 2, -1, 1))
    W = (R - R.T) * (0.5 / np.sinc(angle / np.pi) if angle > 0 else 0.5)
    return np.array([W[2, 1], W[0, 2], W[1, 0]])


class TangentOnGroupTest(unittest.TestCase):
    def test_one_step_tangent_map_on_a_product_of_groups_matches_differences(self):
        """The two-body rigid chain (an inertia that depends on the attitudes) under Crouch-Grossman on
        SO3 x SO3: `varia tangent` against sixth-order differences of one-step runs from
        (R0_k exp(e x_k), p0 + e y), read in the chart at R1, log(R1_k^T R_k)."""
        with open("scenes/multibody/rigid-body-chain-2-s1.json") as f:
            scene = json.load(f)
        scene["method"] = {"construction": "one-step", "one_step": {"type": "crouch-grossman", "order": 2}}
        R0 = [rotation(np.array([0.3, -0.2, 0.1])), rotation(np.array([-0.1, 0.4, 0.2]))]
        q0 = np.concatenate([R.reshape(-1) for R in R0])
        p0 = np.array([0.02, -0.01, 0.03, 0.01, 0.02, -0.015])
        h = 0.02
        with tempfile.TemporaryDirectory() as directory:
            path = os.path.join(directory, "chain.json")
            with open(path, "w") as f:
                json.dump(scene, f)
            done = cli("tangent", path, "--q0", ",".join(repr(x) for x in q0), "--p0",
                       ",".join(repr(x) for x in p0), "--h", repr(h), "--json")
        self.assertEqual(done.returncode, 0, done.stderr)
        result = json.loads(done.stdout)
        exact, q1 = np.array(result["jacobian"]), np.array(result["q1"])

        def step(x):
            q = np.concatenate([(R0[k] @ rotation(x[3 * k:3 * k + 3]) if np.any(x[3 * k:3 * k + 3]) else R0[k])
                                .reshape(-1) for k in range(2)])
            scene["initial"] = {"q": list(q), "p": list(p0 + x[6:])}
            scene["step"], scene["steps"] = h, 1
            scene.pop("t_end", None)
            run = varia.run(scene)
            ends = [run.q[-1][9 * k:9 * k + 9].reshape(3, 3) for k in range(2)]
            local = [rotation_log(q1[9 * k:9 * k + 9].reshape(3, 3).T @ ends[k]) for k in range(2)]
            return np.concatenate(local + [run.p[-1]])

        d = 1e-3
        differences = np.zeros((12, 12))
        for j in range(12):
            e = np.zeros(12)
            e[j] = d
            differences[:, j] = (-step(-3 * e) + 9 * step(-2 * e) - 45 * step(-e) + 45 * step(e) - 9 * step(2 * e)
                                 + step(3 * e)) / (60 * d)
        self.assertLessEqual(np.abs(exact - differences).max(), 1e-9)
        self.assertGreaterEqual(np.abs(exact - np.eye(12)).max(), 1e-3)


class CostTest(unittest.TestCase):
    def test_cost_is_the_cli_cost_json(self):
        scenes = ["scenes/pendulum-galerkin-s1.json", "scenes/pendulum-galerkin-s2.json"]
        with tempfile.TemporaryDirectory() as directory:
            self.assertEqual(cli("cost", *scenes, "--h", "0.2,0.1,0.05,0.025", "--out", directory, "--quiet").returncode, 0)
            with open(os.path.join(directory, "cost.json")) as f:
                expected = json.load(f)
        measured = varia.cost(scenes, h=[0.2, 0.1, 0.05, 0.025])
        for methods in (measured, expected):  # the seconds are the runs' own; everything else is equal
            for method in methods["methods"]:
                self.assertEqual(len(method["rows"]), 4)
                for row in method["rows"]:
                    self.assertGreater(row.pop("seconds"), 0.0)
        self.assertEqual(measured, expected)
        with open(scenes[1]) as f:
            from_dict = varia.cost([json.load(f)], h=[0.2, 0.1, 0.05, 0.025])["methods"][0]
        self.assertEqual(from_dict["method"], "scene0")
        self.assertEqual(from_dict["fitted_slope"], expected["methods"][1]["fitted_slope"])


class DocsTest(unittest.TestCase):
    def test_the_examples_of_docs_python_md_run(self):
        with open("docs/python.md") as f:
            text = f.read()
        blocks = [block.split("```", 1)[0] for block in text.split("```python\n")[1:]]
        self.assertGreaterEqual(len(blocks), 4)
        for block in blocks:
            with self.subTest(block=block.splitlines()[2] if len(block.splitlines()) > 2 else block):
                exec(compile(block, "docs/python.md", "exec"), {})


if __name__ == "__main__":
    unittest.main()
