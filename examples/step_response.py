#!/usr/bin/env python3
"""Runs the digital twin, calibrates it, runs the paper's step response (Section 4.1) and plots
it. Headless: matplotlib's Agg backend writes a PNG.

    make python
    PYTHONPATH=build/release/python python3 examples/step_response.py --out step_response.png
"""
import argparse

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import piezoshift as ps  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--config", help="TOML configuration (default: the paper's values)")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--quick", action="store_true",
                        help="keep the paper's PID gains instead of the grid search")
    parser.add_argument("--out", default="step_response.png", help="PNG to write")
    args = parser.parse_args()

    config = ps.load_project_config(args.config) if args.config else ps.ProjectConfig()
    design = ps.evaluate_design(config.design)
    print(f"k_m = {design.mechanism_stiffness_N_per_um:.3f} N/um, "
          f"x_m = {design.available_displacement_um:.2f} um")

    # The twin alone: 10 V on every DAQ output (150 V on the stacks) for 1.5 s, open loop.
    twin = ps.Twin(config, args.seed)
    _, points_um = twin.run([10.0, 10.0, 10.0], round(1.5 / config.twin.daq.sample_time_s))
    print(f"open loop at 150 V: mean of P1..P3 = {points_um[-1].mean():.3f} um")

    options = ps.CalibrationOptions()
    options.pid = ps.PidChoice.PAPER if args.quick else ps.PidChoice.SEARCH
    cal = ps.calibrate(config, ps.SemiClosedLoopParams(), args.seed, options)
    g = cal.controller.gains
    print(f"calibrated: kp={g.kp} ki={g.ki} kd={g.kd}, A=\n{cal.controller.matrix.a}")

    step = ps.run_step_response(config, cal.controller, args.seed)
    m = step.metrics
    print(f"step {m.step_um:.3f} um: rise {m.rise_time_s * 1e3:.1f} ms, overshoot "
          f"{m.overshoot_pct:.2f} %, settling ({m.band_pct:g} %) {m.settling_time_pct_s:.3f} s")

    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(step.time_s, step.desired_um, "k--", lw=1, label="desired Z_d")
    ax.plot(step.time_s, step.measured_um, lw=1, label="interferometer, mean of P1..P3")
    ax.axvline(m.settling_time_pct_s, color="gray", lw=0.8,
               label=f"settled ({m.band_pct:g} %): {m.settling_time_pct_s:.3f} s")
    ax.set_xlim(step.time_s[0], min(0.3, step.time_s[-1]))  # the paper's Figure 10 spans 0.3 s
    ax.set_xlabel("time since the step [s]")
    ax.set_ylabel("displacement [um]")
    ax.set_title("Semi-closed-loop step response (digital twin)")
    ax.legend(loc="lower right")
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(args.out, dpi=120)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
