#!/usr/bin/env python3
"""PSNR against time per slice on the paper's DeepLesion protocol, from the bench's JSON lines:
FBP, each classical stripe filter (+ FBP), Riner cold and warm-started on 2 CPU cores, and Riner
on a GPU.

  psnr_time_plot.py [OUT.png]     (default bench/figures/deeplesion_psnr_time.png)

Reads the files performance_page.py's SOURCES names. Needs Pillow (Debian: python3-pil).
"""
import math
import os
import statistics
import sys

from PIL import Image, ImageDraw, ImageFont

sys.path.insert(0, os.path.dirname(__file__))
import performance_page as page  # noqa: E402  (SOURCES and the JSONL reader)

ROOT = os.path.normpath(os.path.join(os.path.dirname(__file__), "..", ".."))
W, H = 1000, 640
LEFT, RIGHT, TOP, BOTTOM = 90, 250, 50, 70
T_MIN, T_MAX = 0.05, 300.0
P_MIN, P_MAX = 16.0, 44.0


def points():
    """[(series, label, seconds per slice, PSNR)]."""
    out = []
    classical = page.classical_mean(ROOT)
    fbp_seconds = classical["fbp"]["seconds"] or 0.17
    out.append(("FBP", "FBP", 0.17, classical["fbp"]["psnr"]))
    for name in ("normalise", "sorting", "filtering", "fitting", "wavelet", "large", "all"):
        m = classical[name]
        out.append(("classical + FBP", name, m["seconds"] + fbp_seconds, m["psnr"]))
    for config, slices in page.schedule_runs(ROOT).items():
        warm = page.warm_method(config)
        series = "Riner warm, 2 cores" if warm != "off" else "Riner cold, 2 cores"
        seconds = statistics.fmean(r["seconds"] + r.get("setup_seconds", 0.0) for r in slices)
        psnr = statistics.fmean(r["reconstruct"]["psnr"] for r in slices)
        out.append((series, f"{slices[0]['steps']}", seconds, psnr))
    cpu = page.slices_of(page.records(ROOT, page.SOURCES["deeplesion_cpu"]))
    out.append(("Riner cold, 2 cores", "24000", statistics.fmean(r["seconds"] for r in cpu),
                statistics.fmean(r["reconstruct"]["psnr"] for r in cpu)))
    per = page.gpu_run(ROOT)["per_slice"]
    out.append(("Riner, NVIDIA H200", "24000", statistics.fmean(s["seconds"] for s in per),
                statistics.fmean(s["psnr"] for s in per)))
    oracle = classical["oracle fbp"]["psnr"]
    return out, oracle


def main():
    target = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        ROOT, "bench", "figures", "deeplesion_psnr_time.png")
    data, oracle = points()
    img = Image.new("RGB", (W, H), "white")
    d = ImageDraw.Draw(img)
    font = ImageFont.load_default()

    def x_of(t):
        f = (math.log10(t) - math.log10(T_MIN)) / (math.log10(T_MAX) - math.log10(T_MIN))
        return LEFT + f * (W - LEFT - RIGHT)

    def y_of(p):
        return H - BOTTOM - (p - P_MIN) / (P_MAX - P_MIN) * (H - TOP - BOTTOM)

    d.rectangle([LEFT, TOP, W - RIGHT, H - BOTTOM], outline="black")
    for t in (0.1, 0.3, 1.0, 3.0, 10.0, 30.0, 100.0, 300.0):
        d.line([x_of(t), H - BOTTOM, x_of(t), H - BOTTOM + 5], fill="black")
        d.line([x_of(t), TOP, x_of(t), H - BOTTOM], fill=(230, 230, 230))
        d.text((x_of(t) - 12, H - BOTTOM + 8), f"{t:g} s", fill="black", font=font)
    for p in range(int(P_MIN), int(P_MAX) + 1, 4):
        d.line([LEFT - 5, y_of(p), LEFT, y_of(p)], fill="black")
        d.line([LEFT, y_of(p), W - RIGHT, y_of(p)], fill=(230, 230, 230))
        d.text((LEFT - 40, y_of(p) - 6), f"{p} dB", fill="black", font=font)
    d.line([LEFT, y_of(oracle), W - RIGHT, y_of(oracle)], fill=(120, 120, 120), width=1)
    d.text((LEFT + 6, y_of(oracle) - 14), f"FBP with a perfect detector {oracle:.1f} dB",
           fill=(90, 90, 90), font=font)
    colours = {"FBP": (0, 0, 0), "classical + FBP": (200, 120, 0),
               "Riner cold, 2 cores": (30, 90, 200), "Riner warm, 2 cores": (200, 30, 30),
               "Riner, NVIDIA H200": (30, 150, 60)}
    for series, colour in colours.items():
        pts = sorted((t, p, label) for s, label, t, p in data if s == series)
        if series.startswith("Riner") and len(pts) > 1:
            d.line([(x_of(t), y_of(p)) for t, p, _ in pts], fill=colour, width=2)
        for i, (t, p, label) in enumerate(pts):
            d.ellipse([x_of(t) - 5, y_of(p) - 5, x_of(t) + 5, y_of(p) + 5], fill=colour)
            below = series.startswith("Riner warm") or (series.startswith("classical") and i % 2)
            d.text((x_of(t) + 7, y_of(p) + (4 if below else -14)), label, fill=colour, font=font)
    for i, (series, colour) in enumerate(colours.items()):
        y = TOP + 10 + 22 * i
        d.ellipse([W - RIGHT + 15, y, W - RIGHT + 25, y + 10], fill=colour)
        d.text((W - RIGHT + 32, y), series, fill="black", font=font)
    d.text((LEFT, 15), "DeepLesion, the paper's protocol: ten 256x256 slices, PSNR against "
           "time per slice (labels: filter, or training steps)", fill="black", font=font)
    d.text((LEFT, H - 30), "time per slice (log scale); every point from bench/results "
           "(docs/performance.md)", fill="black", font=font)
    tmp = target + ".tmp.png"
    img.save(tmp)
    os.replace(tmp, target)
    print("wrote " + os.path.relpath(target, ROOT))


if __name__ == "__main__":
    main()
