#!/usr/bin/env python3
"""Compares a calibration's capture-time model with the true one.

Usage: check_time_model.py SUMMARY TRUTH MAX_OFFSET_MS MAX_LINE_DELAY_PERCENT
  SUMMARY  calibration_summary.json of a run (its "capture_time_model")
  TRUTH    ground_truth/time_model.json of rig_calibrator_lab render/synthetic

Prints each camera's estimated and true offset (ms) and line delay (us/row)
with their errors and sigma, then exits 0 when both kinds were kept and
every camera is within the bounds: |offset error| <= MAX_OFFSET_MS and
|line delay error| <= MAX_LINE_DELAY_PERCENT of the true line delay; 1
otherwise, saying which; 2 on unreadable input.
"""
import json
import sys


def main():
    if len(sys.argv) != 5:
        print(__doc__, file=sys.stderr)
        return 2
    try:
        summary = json.load(open(sys.argv[1]))
        truth = json.load(open(sys.argv[2]))
        max_offset_ms = float(sys.argv[3])
        max_delay_percent = float(sys.argv[4])
    except (OSError, ValueError) as error:
        print(f"check_time_model: {error}", file=sys.stderr)
        return 2
    model = summary.get("capture_time_model")
    if model is None:
        print("check_time_model: no capture_time_model in the summary")
        return 1
    print(f"kept: offsets {model['time_offsets_kept']}, line delays "
          f"{model['line_delays_kept']}; RMS {model['rms_without_px']} -> "
          f"{model['rms_px']} px")
    true_cameras = {camera["name"]: camera for camera in truth["cameras"]}
    failures = []
    if not model["time_offsets_kept"]:
        failures.append("the offsets were not kept")
    if not model["line_delays_kept"]:
        failures.append("the line delays were not kept")

    def text(value, scale):
        return "-" if value is None else f"{value * scale:.3f}"

    for camera in model["cameras"]:
        name = camera["name"]
        if name not in true_cameras:
            failures.append(f"{name} is not in {sys.argv[2]}")
            continue
        true = true_cameras[name]
        offset_error_ms = (camera["time_offset_s"] - true["time_offset_s"]) * 1e3
        delay_error = camera["line_delay_s"] - true["line_delay_s"]
        delay_percent = (abs(delay_error) / true["line_delay_s"] * 100
                         if true["line_delay_s"] > 0 else None)
        print(f"{name}: offset {camera['time_offset_s'] * 1e3:+.3f} ms "
              f"(true {true['time_offset_s'] * 1e3:+.3f}, error "
              f"{offset_error_ms:+.3f}, sigma "
              f"{text(camera['time_offset_sigma_s'], 1e3)}); line delay "
              f"{camera['line_delay_s'] * 1e6:.3f} us/row (true "
              f"{true['line_delay_s'] * 1e6:.3f}, error "
              f"{'-' if delay_percent is None else f'{delay_percent:.2f} %'}, "
              f"sigma {text(camera['line_delay_sigma_s'], 1e6)})")
        if abs(offset_error_ms) > max_offset_ms:
            failures.append(f"{name}'s offset is {offset_error_ms:+.3f} ms off "
                            f"(bound {max_offset_ms} ms)")
        if delay_percent is not None and delay_percent > max_delay_percent:
            failures.append(f"{name}'s line delay is {delay_percent:.2f} % off "
                            f"(bound {max_delay_percent} %)")
    for failure in failures:
        print(f"check_time_model: {failure}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
