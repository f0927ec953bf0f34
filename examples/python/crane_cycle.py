"""The whole chain on the reference crane from Python: simulate its load-drop test, identify the
modes (from the record and from plain numpy arrays), tune the joint parameters, validate.

Run with PYTHONPATH pointing at the module's folder (docs/python.md):
    PYTHONPATH=<prefix>/lib/python3/dist-packages python3 crane_cycle.py [SCENARIO]
"""
import sys

import numpy as np

import mbid

path = sys.argv[1] if len(sys.argv) > 1 else mbid.default_scenario_path()
scenario = mbid.load_scenario(path)
print(f"scenario {scenario.name} ({path})")

record = mbid.simulate(scenario)
print(f"simulated {record.samples} samples, channels {sorted(record.channels)}, "
      f"{record.sample_interval_s} s apart")

modes = mbid.identify(record)
for mode in modes.modes:
    print(f"mode {mode.frequency_hz:.4f} Hz, decay {mode.decay_rate_per_s:.4f} 1/s, "
          f"damping ratio {mode.damping_ratio:.4f}")

# The same from arrays, as data from pandas, h5py or a logger's own reader would come.
same = mbid.identify_arrays(record.time, {name: np.asarray(v) for name, v in record.channels.items()})
assert abs(same.modes[0].frequency_hz - modes.modes[0].frequency_hz) < 1e-9

tuned = mbid.update(scenario, [record])
for name, p in sorted(tuned.parameters.items()):
    flag = "" if p.determined else f" (undetermined: {p.why_undetermined})"
    print(f"{name} = {p.value:.6g} +- {p.std:.2g} {p.units}{flag}")

result = mbid.run(scenario)
print(f"verdict: {result.verdict}")
for reason in result.reasons:
    print(f"  because {reason}")

try:
    mbid.load_scenario("no-such-scenario.yaml")
except mbid.InputError as error:
    print(f"bad input is an exception: {error}")
