"""The Python module against independent truth: closed-form signals, unit conversion, the C++
command line's own numbers, and errors with the command line's messages.

Run by ctest with PYTHONPATH=<build>/python; argv[1:]: the mbid binary and the source tree."""
import json
import math
import pathlib
import os
import signal
import subprocess
import sys
import tempfile
import time
import unittest

import numpy as np

import mbid

MBID_BINARY = os.environ["MBID_BINARY"]
SOURCE_DIR = os.environ["MBID_SOURCE_DIR"]
REFERENCE = os.path.join(SOURCE_DIR, "scenarios", "reference-crane.yaml")


class RecordTest(unittest.TestCase):
    def test_simulate_gives_numpy_time_and_channels(self):
        scenario = mbid.load_scenario(REFERENCE)
        record = mbid.simulate(scenario)
        self.assertIsInstance(record.time, np.ndarray)
        self.assertEqual(record.time.shape, (record.samples,))
        # Uniform sampling: t_j = t_0 + j tau (tau from the scenario's sensors, 0.01 s).
        np.testing.assert_allclose(np.diff(record.time), record.sample_interval_s, rtol=1e-12)
        self.assertAlmostEqual(record.sample_interval_s, 0.01, places=15)
        self.assertEqual(sorted(record.channels), ["phi", "psi"])
        for values in record.channels.values():
            self.assertIsInstance(values, np.ndarray)
            self.assertEqual(values.shape, record.time.shape)
        self.assertEqual(record.units["psi"], "rad")

    def test_read_record_converts_degrees_to_radians(self):
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, "logger.csv")
            with open(path, "w") as f:
                f.write("time [s],psi [deg]\n")
                for j in range(50):
                    f.write(f"{0.02 * j:.2f},{30.0 + j}\n")
            record = mbid.read_record(path)
        self.assertEqual(record.units["psi"], "rad")
        # deg -> rad by udunits2: exactly pi / 180 per degree.
        np.testing.assert_allclose(record.channels["psi"],
                                   np.radians(30.0 + np.arange(50)), rtol=1e-12)
        self.assertAlmostEqual(record.sample_interval_s, 0.02, places=12)


class IdentifyTest(unittest.TestCase):
    def test_identify_arrays_recovers_a_closed_form_decay(self):
        # y = exp(-0.3 t) cos(2 pi 2 t) + 0.5 exp(-0.8 t) sin(2 pi 5.5 t): two modes whose
        # frequencies and decay rates are exact; noise-free, they come back to 1e-6 relative.
        t = np.arange(2000) * 0.005
        y = (np.exp(-0.3 * t) * np.cos(2 * np.pi * 2.0 * t)
             + 0.5 * np.exp(-0.8 * t) * np.sin(2 * np.pi * 5.5 * t))
        result = mbid.identify_arrays(t, {"x": y}, {"x": "m"})
        self.assertEqual(len(result.modes), 2)
        self.assertLess(result.residual_to_noise[0], 3)  # both modes: nothing left
        self.assertAlmostEqual(result.modes[0].frequency_hz, 2.0, delta=2e-6)
        self.assertAlmostEqual(result.modes[0].decay_rate_per_s, 0.3, delta=3e-7)
        self.assertAlmostEqual(result.modes[1].frequency_hz, 5.5, delta=5.5e-6)
        self.assertAlmostEqual(result.modes[1].decay_rate_per_s, 0.8, delta=8e-7)
        # damping ratio = decay / |lambda| by definition.
        mode = result.modes[0]
        self.assertAlmostEqual(mode.damping_ratio,
                               0.3 / math.hypot(0.3, 2 * math.pi * 2.0), delta=1e-7)

    def test_a_knock_after_the_decay_came_to_rest_ends_the_analysis(self):
        # 1 s at rest at the deflection, a 2 Hz decay at 2 1/s (at rest within the 1e-4 noise
        # from about 6 s), then at 12 s a knock: the analysis ends before it (C++:
        # NextExcitationTest), and the mode is the first decay's.
        rng = np.random.default_rng(1)
        t = np.arange(3000) * 0.005
        s = t - 1.0
        y = np.where(t < 1.0, 1.0, np.exp(-2.0 * s) * np.cos(2 * np.pi * 2.0 * s))
        k = t - 12.0
        y = y + np.where(t >= 12.0, np.exp(-2.0 * k) * np.sin(2 * np.pi * 2.0 * k), 0.0)
        y = y + 1e-4 * rng.standard_normal(t.size)
        result = mbid.identify_arrays(t, {"x": y}, {"x": "m"})
        self.assertIsNotNone(result.next_excitation_s)
        self.assertAlmostEqual(result.next_excitation_s, 12.0, delta=0.011)
        self.assertEqual(len(result.modes), 1)
        self.assertAlmostEqual(result.modes[0].frequency_hz, 2.0, delta=1e-3)
        quiet = mbid.identify_arrays(t[t < 12.0], {"x": y[t < 12.0]}, {"x": "m"})
        self.assertIsNone(quiet.next_excitation_s)

    def test_options_reach_the_identification(self):
        # The two-mode decay above. A band up to 4 Hz keeps the 2 Hz mode alone (within two of
        # its standard deviations), and since one mode cannot explain the record the result says
        # so. The paper's prony-svd finds both modes (noise-free: to 1e-6 relative).
        t = np.arange(2000) * 0.005
        y = (np.exp(-0.3 * t) * np.cos(2 * np.pi * 2.0 * t)
             + 0.5 * np.exp(-0.8 * t) * np.sin(2 * np.pi * 5.5 * t))
        options = mbid.IdentificationOptions()
        self.assertEqual(options.method, "hankel-nls")
        options.max_frequency_hz = 4.0
        banded = mbid.identify_arrays(t, {"x": y}, {"x": "m"}, options)
        self.assertEqual(len(banded.modes), 1)
        mode = banded.modes[0]
        self.assertAlmostEqual(mode.frequency_hz, 2.0, delta=2 * mode.std_frequency_hz)
        self.assertFalse(banded.reliable)
        # Its margin says by how much: the 5.5 Hz mode left in the residual, far above 3.
        self.assertEqual(banded.residual_to_noise.shape, (1,))
        self.assertGreater(banded.residual_to_noise[0], 3)
        prony = mbid.IdentificationOptions()
        prony.method = "prony-svd"
        prony.release = "none"
        record = mbid.identify_arrays(t, {"x": y}, {"x": "m"}, options=prony)
        self.assertEqual(len(record.modes), 2)
        self.assertAlmostEqual(record.modes[1].frequency_hz, 5.5, delta=5.5e-6)
        with self.assertRaises(mbid.InputError):
            prony.method = "fft"
        with self.assertRaises(mbid.InputError):
            prony.release = "later"
        # The options of issue 13: backbones on request, drift removal (names round-trip).
        self.assertEqual(options.backbone, "clusters")
        options.backbone = "always"
        self.assertEqual(options.backbone, "always")
        with self.assertRaises(mbid.InputError):
            options.backbone = "sometimes"
        self.assertFalse(options.remove_drift)
        options.remove_drift = True
        self.assertTrue(options.remove_drift)

    def test_a_clipped_start_is_skipped_unless_kept(self):
        # exp(-0.3 t) cos(2 pi 2 t) held at 0.6 (a logger's range): its peaks, every 0.5 s,
        # reach exp(-0.15 k); the one at 1.5 s (0.64) is the last clipped, and the decay after it
        # is whole, so its pole comes back to 1e-5 relative. Kept, the record is unreliable.
        t = np.arange(2000) * 0.005
        y = np.minimum(np.exp(-0.3 * t) * np.cos(2 * np.pi * 2.0 * t), 0.6)
        result = mbid.identify_arrays(t, {"x": y}, {"x": "m"})
        self.assertTrue(result.reliable, result.reasons)
        self.assertGreater(result.start_time_s, 1.5)
        self.assertLess(result.start_time_s, 2.0)
        self.assertEqual(len(result.modes), 1)
        self.assertAlmostEqual(result.modes[0].frequency_hz, 2.0, delta=2e-5)
        self.assertAlmostEqual(result.modes[0].decay_rate_per_s, 0.3, delta=3e-6)
        options = mbid.IdentificationOptions()
        self.assertTrue(options.skip_clipped)
        options.skip_clipped = False
        kept = mbid.identify_arrays(t, {"x": y}, {"x": "m"}, options)
        self.assertFalse(kept.reliable)
        self.assertIn("(clipped)", kept.reasons[0])

    def test_identify_of_a_record_equals_identify_of_its_arrays(self):
        record = mbid.simulate(mbid.load_scenario(REFERENCE))
        a = mbid.identify(record)
        b = mbid.identify_arrays(record.time, record.channels, record.units)
        # Same modes; the time grid re-fitted from the array may differ in its last bits.
        self.assertEqual(len(a.modes), len(b.modes))
        for x, y in zip(a.modes, b.modes):
            self.assertAlmostEqual(x.frequency_hz, y.frequency_hz, delta=1e-9 * x.frequency_hz)
            self.assertAlmostEqual(x.decay_rate_per_s, y.decay_rate_per_s,
                                   delta=1e-9 * x.decay_rate_per_s)

    def test_identify_with_the_scenario_starts_after_a_hammer_blow(self):
        # A three-storey shear frame hit at the roof for 10 ms: from the record's start a fourth
        # "mode" absorbs the pulse; with its scenario the record is analysed after it, as
        # mbid run does, and the modes are the model's (mbid modes) within 1e-4.
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, "frame.yaml")
            floor = ("{parent: %s, joint: {type: prismatic, coordinates: [%s], axis: [1, 0, 0]}, "
                     "mass_kg: 1000.0, inertia_kgm2: [100, 100, 100]}")
            with open(path, "w") as out:
                out.write("name: frame\nmodel:\n  type: multibody\n  bodies:\n"
                          "    f1: " + floor % ("ground", "x1") + "\n"
                          "    f2: " + floor % ("f1", "x2") + "\n"
                          "    f3: " + floor % ("f2", "x3") + "\n"
                          "  springs:\n"
                          "    x1: {stiffness_N_per_m: 1.2e6, damping_Ns_per_m: 300.0}\n"
                          "    x2: {stiffness_N_per_m: 1.0e6, damping_Ns_per_m: 200.0}\n"
                          "    x3: {stiffness_N_per_m: 0.8e6, damping_Ns_per_m: 200.0}\n"
                          "  points: {roof: {body: f3, at_m: [0, 0, 0]}}\n"
                          "  outputs: {a_roof: {type: acceleration, point: roof, "
                          "direction: [1, 0, 0]}}\n"
                          "excitation: {type: impulse, point: roof, force_N: [20000, 0, 0], "
                          "duration_s: 0.01}\n"
                          "simulation: {duration_s: 6}\n"
                          "sensors: {sample_rate_hz: 200, channels: [a_roof], "
                          "noise_std_mps2: 2.0e-3, seed: 4}\n")
            scenario = mbid.load_scenario(path)
            exact = json.loads(subprocess.run([MBID_BINARY, "modes", path, "--json", "-"],
                                              check=True, capture_output=True,
                                              text=True).stdout)["modes"]
            # The record's file carries its scenario: identify(path) reads it as the command
            # line does (it analysed the blow as a decay: 31 "modes" in a trial).
            h5 = os.path.join(folder, "frame.h5")
            subprocess.run([MBID_BINARY, "simulate", path, "-o", h5], check=True,
                           capture_output=True)
            from_file = mbid.identify(h5)
            self.assertEqual(from_file.release, "forcing end")
            self.assertEqual(from_file.release_time_s, 0.01)
            self.assertEqual(len(from_file.modes), 3)
        record = mbid.simulate(scenario)
        # Without the scenario the decay starts at the blow, which no mode describes.
        plain = mbid.identify(record)
        self.assertFalse(plain.reliable)
        self.assertTrue(any("jumps off its course" in r for r in plain.reasons), plain.reasons)
        result = mbid.identify(record, scenario=scenario)
        self.assertTrue(result.reliable, result.reasons)
        self.assertEqual(len(result.modes), 3)
        for mode, truth in zip(result.modes, exact):
            self.assertAlmostEqual(mode.frequency_hz, truth["frequency_hz"],
                                   delta=1e-4 * truth["frequency_hz"])


class UpdateAndRunTest(unittest.TestCase):
    def test_update_equals_the_command_line(self):
        # The module and `mbid update` run the same code on the same record: same bits.
        scenario = mbid.load_scenario(REFERENCE)
        with tempfile.TemporaryDirectory() as folder:
            h5 = os.path.join(folder, "test.h5")
            subprocess.run([MBID_BINARY, "simulate", REFERENCE, "-o", h5, "--quiet"], check=True)
            record = mbid.read_record(h5)
            out = os.path.join(folder, "update.json")
            subprocess.run([MBID_BINARY, "update", REFERENCE, h5, "--json", out, "--quiet"],
                           check=True, stdout=subprocess.DEVNULL)
            with open(out) as f:
                cli = json.load(f)
        tuned = mbid.update(scenario, [record])
        self.assertTrue(tuned.converged)
        for name, entry in cli["parameters"].items():
            self.assertIn(name, tuned.parameters)
            self.assertEqual(tuned.parameters[name].value, entry["value"], name)
            self.assertEqual(tuned.parameters[name].std, entry["std"], name)
        self.assertGreater(tuned.parameters["c_alpha"].std, 0.0)
        # Where the record's free decay starts, as the command reports it.
        self.assertEqual(tuned.release, [cli["release"][0]["release"]])
        self.assertEqual(tuned.release_time_s, [cli["release"][0]["release_time_s"]])
        # The scenario does not ask for profile-likelihood intervals: NaN, not a number made up.
        self.assertTrue(math.isnan(tuned.parameters["c_alpha"].profile_lower))
        self.assertFalse(tuned.parameters["c_alpha"].profile_upper_open)

    def test_run_gives_the_verdict_as_text(self):
        result = mbid.run(mbid.load_scenario(REFERENCE))
        # The reference crane's own simulated test validates (docs/validation.md).
        self.assertEqual(result.verdict, "passed")
        self.assertEqual(result.reasons, [])
        self.assertGreaterEqual(min(result.correlation.values()), result.min_correlation)


class InterruptTest(unittest.TestCase):
    # Ctrl-C during a long call: Python's handler runs only between bytecodes, and a run went on
    # for 25 s, its gnuplot children died and a "gnuplot failed" RuntimeError came first, the
    # KeyboardInterrupt later inside the user's except block. Now the call stops within a moment
    # and raises KeyboardInterrupt, leaving no output folder. The crane's test of 300 s at 400 Hz
    # runs for minutes uninterrupted (37 s for 60 s on this host): ending within 60 s of the
    # signal can only be the stop.
    CHILD = """
import os, signal, sys, time
import mbid
scenario = mbid.load_scenario_text(open(sys.argv[1]).read().replace(
    "duration_s: 8", "duration_s: 300").replace("sample_rate_hz: 100", "sample_rate_hz: 400"),
    sys.argv[1])
call = {"run": lambda: mbid.run(scenario, output_folder=sys.argv[2]),
        "update": lambda: mbid.update(scenario, [mbid.simulate(scenario)])}[sys.argv[3]]
print("calling", flush=True)
try:
    call()
    print("finished")
except KeyboardInterrupt:
    print("KeyboardInterrupt")
print("handler restored:", signal.getsignal(signal.SIGINT) is signal.default_int_handler)
"""

    def interrupt(self, what):
        with tempfile.TemporaryDirectory() as folder:
            out = os.path.join(folder, "run")
            # SIGINT at its default in the child (a background job's would be ignored).
            child = subprocess.Popen(
                [sys.executable, "-c", self.CHILD, REFERENCE, out, what],
                stdout=subprocess.PIPE, text=True,
                preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
            self.assertEqual(child.stdout.readline().strip(), "calling")
            time.sleep(1.0)  # inside the call: the simulation alone takes longer
            child.send_signal(signal.SIGINT)
            output, _ = child.communicate(timeout=60)
            self.assertEqual(output.split("\n")[:2],
                             ["KeyboardInterrupt", "handler restored: True"], output)
            self.assertFalse(os.path.exists(out))
            self.assertEqual(os.listdir(folder), [])  # no staging folder left either

    def test_ctrl_c_stops_a_run_with_an_output_folder(self):
        self.interrupt("run")

    def test_ctrl_c_stops_an_update(self):
        self.interrupt("update")


class ErrorTest(unittest.TestCase):
    def test_a_missing_scenario_is_an_input_error_with_the_commands_message(self):
        with self.assertRaises(mbid.InputError) as raised:
            mbid.load_scenario("no-such-scenario.yaml")
        message = str(raised.exception)
        self.assertTrue(message.startswith("no-such-scenario.yaml:"), message)
        self.assertEqual(message.count("\n"), 0)
        self.assertIsInstance(raised.exception, ValueError)
        cli = subprocess.run([MBID_BINARY, "run", "no-such-scenario.yaml"],
                             capture_output=True, text=True)
        self.assertEqual(cli.returncode, 2)
        self.assertIn(message, cli.stderr)

    def test_non_uniform_time_names_the_sample(self):
        t = np.array([0.0, 0.1, 0.2, 0.35, 0.4])
        with self.assertRaises(mbid.InputError) as raised:
            mbid.identify_arrays(t, {"x": np.ones(5)})
        self.assertIn("time[", str(raised.exception))

    def test_single_precision_times_are_read_to_their_last_bit(self):
        # A logger's float32 clock: 20 s at 1 kHz is off the grid by up to half a float32 ulp
        # of 20 (1 us, a thousandth of the step; 7e-7 relative to the step in the worst sample,
        # which the double-precision test would refuse). The 2 Hz decay comes back as with
        # exact times, and a dropped sample is still found.
        t64 = np.arange(20000) * 0.001
        y = np.exp(-0.3 * t64) * np.cos(2 * np.pi * 2.0 * t64)
        t32 = t64.astype(np.float32)
        result = mbid.identify_arrays(t32, {"x": y}, {"x": "m"})
        self.assertAlmostEqual(result.modes[0].frequency_hz, 2.0, delta=1e-5)
        self.assertAlmostEqual(result.sample_interval_s, 0.001, delta=1e-9)
        dropped = np.delete(t32, 5000)
        with self.assertRaises(mbid.InputError) as raised:
            mbid.identify_arrays(dropped, {"x": np.delete(y, 5000)})
        self.assertIn("time[5000]", str(raised.exception))

    def test_times_that_are_no_numbers_are_refused_in_one_line(self):
        # Strings, lists of strings, objects: an InputError naming `time`, never a crash (a
        # string once reached a null array's dimension).
        for bad in ["abc", ["a"] * 20, np.array(["a"] * 20), [0.0, "x", 0.2], {"t": 1}, None]:
            with self.assertRaises(mbid.InputError, msg=repr(bad)) as raised:
                mbid.identify_arrays(bad, {"x": np.zeros(20)})
            self.assertIn("identify_arrays:time", str(raised.exception).replace(" ", ""))
            self.assertEqual(str(raised.exception).count("\n"), 0)

    def test_channels_of_no_real_numbers_are_refused_in_one_line(self):
        # A complex channel lost its imaginary part behind numpy's ComplexWarning; strings were
        # refused by pybind's multi-line TypeError. Each is an InputError naming the channel.
        t = np.arange(20) * 0.01
        for bad in [np.ones(20) * (1 + 1j), ["a"] * 20, np.ones((20, 2))]:
            with self.assertRaises(mbid.InputError, msg=repr(bad)) as raised:
                mbid.identify_arrays(t, {"x": bad})
            self.assertIn("identify_arrays:channels/x", str(raised.exception).replace(" ", ""))
            self.assertEqual(str(raised.exception).count("\n"), 0)

    def test_epoch_times_in_float64_are_read_to_their_last_bit(self):
        # Unix times of 2023 (1.7e9 s) at 200 Hz: float64 holds them to 2.4e-7 s, 5e-5 of the
        # step, above the 1e-6 a time column's uniformity is held to; a file's HDF5 time vector
        # of the same values is read (its own resolution), and so are these.
        t = 1.7e9 + np.arange(2000) * 0.005
        y = np.exp(-0.3 * (t - t[0])) * np.cos(2 * np.pi * 2.0 * (t - t[0]))
        result = mbid.identify_arrays(t, {"x": y}, {"x": "m"})
        self.assertAlmostEqual(result.modes[0].frequency_hz, 2.0, delta=1e-5)

    def test_a_channel_of_the_wrong_length_is_refused(self):
        with self.assertRaises(mbid.InputError) as raised:
            mbid.identify_arrays(np.arange(10) * 0.1, {"x": np.ones(9)})
        self.assertIn("channels/x", str(raised.exception))

    def test_paths_may_be_pathlib_paths(self):
        scenario = mbid.load_scenario(pathlib.Path(mbid.default_scenario_path()))
        self.assertEqual(scenario.name, "reference-crane")
        with self.assertRaises(mbid.InputError) as raised:
            mbid.read_record(pathlib.Path("/nonexistent/record.csv"))
        self.assertIn("/nonexistent/record.csv", str(raised.exception))

    def test_scenarios_and_records_may_be_given_as_their_files(self):
        # A path where a Scenario or Record is expected is read as load_scenario / read_record
        # would: the same bits as the objects give.
        with tempfile.TemporaryDirectory() as folder:
            h5 = pathlib.Path(folder) / "test.h5"
            subprocess.run([MBID_BINARY, "simulate", REFERENCE, "-o", str(h5), "--quiet"],
                           check=True)
            by_path = mbid.update(REFERENCE, [h5])
            by_object = mbid.update(mbid.load_scenario(REFERENCE), [mbid.read_record(h5)])
            single = mbid.update(REFERENCE, str(h5))  # one record, not in a list
            identified = mbid.identify(str(h5))
            self.assertEqual(identified.modes[0].frequency_hz,
                             mbid.identify(mbid.read_record(h5)).modes[0].frequency_hz)
        for name in ["c_alpha", "d_theta"]:
            self.assertEqual(by_path.parameters[name].value, by_object.parameters[name].value)
            self.assertEqual(single.parameters[name].value, by_object.parameters[name].value)
        simulated = mbid.simulate(pathlib.Path(REFERENCE))
        np.testing.assert_array_equal(simulated.time,
                                      mbid.simulate(mbid.load_scenario(REFERENCE)).time)
        self.assertEqual(mbid.run(REFERENCE).verdict, "passed")

    def test_a_fit_whose_simulations_fail_is_neither_converged_nor_credible(self):
        # The integrator allowed 10 steps: every simulation of the fit fails. The result said
        # converged False but credible True (the default of a fit never judged), and Ceres' glog
        # lines reached stderr; now neither.
        with tempfile.TemporaryDirectory() as folder:
            h5 = os.path.join(folder, "test.h5")
            subprocess.run([MBID_BINARY, "simulate", REFERENCE, "-o", h5, "--quiet"], check=True)
            with open(REFERENCE) as f:
                text = f.read().replace("integrator: {method: auto,",
                                        "integrator: {max_steps: 10, method: auto,")
            self.assertIn("max_steps: 10", text)
            starved = os.path.join(folder, "starved.yaml")
            with open(starved, "w") as f:
                f.write(text + "updating: {global_search: {enabled: false}}\n")
            script = ("import mbid; r = mbid.update(%r, [%r]); print(r.converged, r.credible)"
                      % (starved, h5))
            run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                                 env=dict(os.environ))
        self.assertEqual(run.returncode, 0, run.stderr)
        self.assertEqual(run.stdout.split(), ["False", "False"])
        self.assertNotIn("InitGoogleLogging", run.stderr)
        self.assertNotIn("Terminating:", run.stderr)

    def test_arguments_of_the_wrong_type_are_refused_in_one_line(self):
        # pybind11's own TypeError lists every signature over several lines; these name the
        # function, the argument and what it takes.
        cases = [(lambda: mbid.load_scenario(3), "load_scenario(): path is of type int"),
                 (lambda: mbid.read_record(None), "read_record(): path is of type NoneType"),
                 (lambda: mbid.simulate(3.5), "simulate(): scenario is of type float"),
                 (lambda: mbid.identify({}), "identify(): record is of type dict"),
                 (lambda: mbid.update(REFERENCE, 7), "update(): records is of type int"),
                 (lambda: mbid.update(REFERENCE, [7]), "update(): records[0] is of type int"),
                 (lambda: mbid.run([]), "run(): scenario is of type list"),
                 # These were pybind11's 4-6 lines (a trial's):
                 (lambda: mbid.run(REFERENCE, output_folder=5),
                  "run(): output_folder is of type int"),
                 (lambda: mbid.identify_arrays(np.arange(3.0), {1: np.arange(3.0)}),
                  "identify_arrays(): a key of channels is of type int"),
                 (lambda: mbid.identify_arrays(np.arange(3.0), [np.arange(3.0)]),
                  "identify_arrays(): channels is of type list"),
                 (lambda: mbid.identify_arrays(np.arange(3.0), {"a": np.arange(3.0)}, {"a": 3}),
                  "identify_arrays(): units['a'] is of type int")]
        for call, start in cases:
            with self.assertRaises(TypeError) as raised:
                call()
            message = str(raised.exception)
            self.assertTrue(message.startswith(start), message)
            self.assertEqual(message.count("\n"), 0, message)

    def test_a_record_file_is_named_by_its_path_and_advice_fits_the_call(self):
        # update() named a file given by its path "record 1"; the command line names the file.
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, "unknown.csv")
            with open(path, "w") as f:
                f.write("time,zzz\n0,1\n0.01,2\n0.02,1\n0.03,0\n")
            with self.assertRaises(mbid.InputError) as raised:
                mbid.update(REFERENCE, [path])
            self.assertTrue(str(raised.exception).startswith(path + ":channels:"),
                            str(raised.exception))
        # float16 times of a 200 Hz record repeat near 8 s: the advice was a record entry's
        # sample_rate_hz, which identify_arrays has not; it names times made from the rate.
        t = (np.arange(2000) * 0.005).astype(np.float16)
        with self.assertRaises(mbid.InputError) as raised:
            mbid.identify_arrays(t, {"a": np.cos(t.astype(float))}, {"a": "m"})
        self.assertNotIn("sample_rate_hz", str(raised.exception))
        self.assertIn("numpy.arange(n) / rate_hz", str(raised.exception))

    def test_units_are_converted_to_si_or_refused(self):
        # A unit decay stated in deg comes back with amplitude pi / 180 rad, as a file's would;
        # a unit udunits2 does not know, and the ambiguous 'g', are refused with the channel.
        t = np.arange(2000) * 0.01
        y = np.exp(-0.1 * t) * np.cos(2 * np.pi * 1.5 * t)
        result = mbid.identify_arrays(t, {"x": y}, {"x": "deg"})
        self.assertAlmostEqual(result.modes[0].amplitude[0], math.pi / 180, delta=1e-9)
        for unit in ["furlongs_per_bogus", "g"]:
            with self.assertRaises(mbid.InputError) as raised:
                mbid.identify_arrays(t, {"x": y}, {"x": unit})
            self.assertIn("units/x", str(raised.exception))


if __name__ == "__main__":
    unittest.main()
