"""The example of docs/python.md, cell by cell; its printed lines and figure are the doc's.

  PYTHONPATH=build/python /usr/bin/python3 python/example.py docs

writes docs/python-inplane.png (and fabric.exr, verify-report/ in a temporary folder).
"""
import pathlib
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import weft  # noqa: E402

figures = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".")
work = pathlib.Path(tempfile.mkdtemp(prefix="weft-example-"))

# --- 1. Bake a fiber: the red-cotton preset, in RGB, a quick bake (R = 8, 20 000 photons/band).
fiber = weft.bake_fiber("red-cotton", photons=20000, resolution=8, bands="rgb", seed=1)
print(fiber, fiber.values.shape, fiber.values.dtype)
print("fiber albedo (R, G, B):", np.round(fiber.total_albedo(), 4))

# --- 2. A fabric table: the paper's summation over the bundled poplin, saved and loaded back.
fabric = weft.bake_fabric(fiber, "summation", resolution=8)
fabric.save(work / "fabric.exr")
fabric = weft.load_table(work / "fabric.exr")
print(fabric, fabric.metadata["sample"])
up = fabric.albedo([0, 0, 1])  # light along the normal: where it goes
print("reflected:", np.round(up["reflectance"], 4), "transmitted:", np.round(up["transmittance"], 4))

# --- 3. A slice: the in-plane BRDF (plane of the warp, x) for light at 30 degrees.
theta_i = np.radians(30)
wi = [-np.sin(theta_i), 0, np.cos(theta_i)]
views = np.radians(np.linspace(-85, 85, 171))
f = np.array([fabric.eval([np.sin(t), 0, np.cos(t)], wi) for t in views])
fig, ax = plt.subplots(figsize=(5, 3.2))
for c, colour in enumerate(["tab:red", "tab:green", "tab:blue"]):
    ax.plot(np.degrees(views), f[:, c], color=colour, label="RGB"[c])
ax.set_xlabel("view zenith angle (deg), light at -30 deg")
ax.set_ylabel("f (1/sr)")
ax.set_title("red cotton poplin, paper's summation, R = 8")
ax.legend()
fig.tight_layout()
fig.savefig(figures / "python-inplane.png", dpi=100)
print("f at the mirror direction (R, G, B):", np.round(fabric.eval([np.sin(theta_i), 0, np.cos(theta_i)], wi), 4))

# --- 4. weft verify at draft quality: the report folder, and metrics.json as a dict.
metrics = weft.verify("draft", output=work / "verify-report", plots=False)
print("report folder:", pathlib.Path(metrics["report_folder"]).name, "quality:", metrics["settings"]["quality"])
for key, model in metrics["models"].items():
    print(f"  {key:<20} RMS log vs measured: normalized {model['normalized']['rms_log']:.3f},"
          f" absolute {model['absolute']['rms_log']:.3f}")
