#!/usr/bin/env python3
"""Real-data calibration cases from a COLMAP map of a rig, and their check
(scripts/real_data_check.sh). Needs python3 and numpy.

  split MAP_TXT OUT_DIR HOLDOUT
      MAP_TXT is a COLMAP text model whose images are named
      <camera>/<timestamp>.<ext>, every camera its own COLMAP camera, the rig
      never declared (as COLMAP's mapper registers the images of a rig that
      it does not know). The timestamps (sorted) are split: HOLDOUT is
      "mod:K:R" (hold out the timestamps whose index i has i % K == R) or
      "range:A:B" (hold out indices A <= i < B). Writes
        OUT_DIR/map/{cameras,images,points3D}.txt   the map without the
            held-out images and their observations; points seen by fewer
            than 2 remaining images are dropped
        OUT_DIR/correspondences.txt   the held-out images' observations of
            the remaining points, in rig_calibrator's correspondence format
        OUT_DIR/reference.json   per camera: the map's intrinsics, and the
            map's rig (cam_from_rig, rig = the first camera) as the mean of
            the per-timestamp rigs of the map's timestamps, with the
            per-timestamp scatter and the standard error of that mean.
      The held-out timestamps are the calibration's framesets; the reference
      comes from the others, so the two are independent draws of the map's
      per-timestamp rig.
  euroc-reference SENSOR0_YAML SENSOR1_YAML OUT_JSON
      The EuRoC pair's pattern calibration (the dataset's sensor.yaml) as a
      reference.json: OPENCV intrinsics with the principal point moved to
      COLMAP's pixel centres (+0.5), cam1's pose from T_BS; a pattern
      reference, so its own standard error is taken as 0.
  compare REFERENCE_JSON SUMMARY_JSON [--label NAME] [--table FILE]
      Per camera: the calibration's error against the reference (rotation,
      centre in the rig, focal length, principal point), the σ the
      calibration reports, the reference's own standard error, and
      z = |error| / sqrt(σ² + reference_se²) (rotation and centre: the norm
      of the per-axis error over the norm of the per-axis combined σ; focal
      length: the calibration's σ only, the reference's own is unknown), and
      the verdict: "within 3 sigma" (every z <= 3), "flagged" (a warning or
      error names the camera), else "OFF AND SILENT"; or "NOT CALIBRATED".
      The principal point is printed, not judged (the ring's map held it at
      the image centre). Prints a table; appends JSON rows to FILE.
  verdicts TABLE
      Counts the verdicts of every row; exit 1 when a camera is not
      calibrated or off and silent.
"""
import argparse
import json
import math
import os
import re
import sys

import numpy as np


def die(message):
    sys.stderr.write("[real_data_tools] ERROR: %s\n" % message)
    sys.exit(1)


# ---------------------------------------------------------------------------
# COLMAP text model.

def records(path):
    """The fields of every line of a COLMAP text file that is no comment."""
    for line in open(path):
        if not line.startswith("#") and line.strip():
            yield line.split()


def read_cameras(path):
    cameras = {}
    for f in records(path):
        cameras[int(f[0])] = {"model": f[1], "width": int(f[2]),
                              "height": int(f[3]),
                              "params": [float(x) for x in f[4:]]}
    return cameras


def read_images(path):
    images = {}
    lines = [l for l in open(path) if not l.startswith("#")]
    for k in range(0, len(lines) - 1, 2):
        f = lines[k].split()
        if not f:
            continue
        obs = lines[k + 1].split()
        points = [(float(obs[i]), float(obs[i + 1]), int(obs[i + 2]))
                  for i in range(0, len(obs) - 2, 3)]
        images[int(f[0])] = {"q": [float(x) for x in f[1:5]],
                             "t": [float(x) for x in f[5:8]],
                             "camera_id": int(f[8]), "name": f[9],
                             "points2D": points}
    return images


def read_points(path):
    points = {}
    for f in records(path):
        track = [(int(f[i]), int(f[i + 1])) for i in range(8, len(f) - 1, 2)]
        points[int(f[0])] = {"xyz": [float(x) for x in f[1:4]],
                             "rgb": f[4:7], "error": f[7], "track": track}
    return points


def quat_to_matrix(q):
    w, x, y, z = q
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def matrix_to_quat(R):
    # The eigenvector of the largest eigenvalue of Bar-Itzhack's 4x4 matrix:
    # robust for every rotation.
    K = np.array([
        [R[0, 0] - R[1, 1] - R[2, 2], R[1, 0] + R[0, 1], R[2, 0] + R[0, 2],
         R[2, 1] - R[1, 2]],
        [R[1, 0] + R[0, 1], R[1, 1] - R[0, 0] - R[2, 2], R[2, 1] + R[1, 2],
         R[0, 2] - R[2, 0]],
        [R[2, 0] + R[0, 2], R[2, 1] + R[1, 2], R[2, 2] - R[0, 0] - R[1, 1],
         R[1, 0] - R[0, 1]],
        [R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1],
         R[0, 0] + R[1, 1] + R[2, 2]]]) / 3.0
    values, vectors = np.linalg.eigh(K)
    x, y, z, w = vectors[:, np.argmax(values)]
    q = np.array([w, x, y, z])
    return q if w >= 0 else -q


def rotation_angle_deg(R):
    return math.degrees(math.acos(max(-1.0, min(1.0, (np.trace(R) - 1) / 2))))


def rotation_log(R):
    """Axis-angle vector (radians) of R."""
    angle = math.acos(max(-1.0, min(1.0, (np.trace(R) - 1) / 2)))
    if angle < 1e-12:
        return np.zeros(3)
    w = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    return w * angle / (2 * math.sin(angle))


def mean_rotation(rotations):
    """Chordal L2 mean: the rotation nearest to the sum of the matrices."""
    U, _, Vt = np.linalg.svd(sum(rotations))
    D = np.diag([1, 1, np.sign(np.linalg.det(U @ Vt))])
    return U @ D @ Vt


def split_name(name):
    if "/" not in name:
        die("image %s is not named <camera>/<timestamp>" % name)
    camera, file_name = name.split("/", 1)
    return camera, file_name.rsplit(".", 1)[0]


def write_model(out, cameras, images, points):
    with open(out + "/cameras.txt", "w") as f:
        f.write("# Camera list with one line of data per camera:\n")
        for cid in sorted(cameras):
            c = cameras[cid]
            f.write("%d %s %d %d %s\n" % (cid, c["model"], c["width"],
                                          c["height"],
                                          " ".join(repr(p) for p in c["params"])))
    with open(out + "/images.txt", "w") as f:
        f.write("# Image list with two lines of data per image:\n")
        for iid in sorted(images):
            im = images[iid]
            f.write("%d %s %s %d %s\n" % (
                iid, " ".join(repr(v) for v in im["q"]),
                " ".join(repr(v) for v in im["t"]), im["camera_id"],
                im["name"]))
            f.write(" ".join("%r %r %d" % p for p in im["points2D"]) + "\n")
    with open(out + "/points3D.txt", "w") as f:
        f.write("# 3D point list with one line of data per point:\n")
        for pid in sorted(points):
            p = points[pid]
            f.write("%d %s %s %s %s\n" % (
                pid, " ".join(repr(v) for v in p["xyz"]), " ".join(p["rgb"]),
                p["error"], " ".join("%d %d" % o for o in p["track"])))


def parse_holdout(spec, count):
    parts = spec.split(":")
    try:
        if parts[0] == "mod" and len(parts) == 3:
            k, r = int(parts[1]), int(parts[2])
            if k < 2 or not 0 <= r < k:
                raise ValueError
            return [i for i in range(count) if i % k == r]
        if parts[0] == "range" and len(parts) == 3:
            a, b = int(parts[1]), int(parts[2])
            if not 0 <= a < b <= count:
                raise ValueError
            return list(range(a, b))
    except ValueError:
        pass
    die("HOLDOUT must be mod:K:R (K >= 2, 0 <= R < K) or range:A:B "
        "(0 <= A < B <= %d), got '%s'" % (count, spec))


def per_timestamp_rigs(images, cameras_by_name, reference_camera, timestamps):
    """{camera: [(R, centre_in_rig)]} over the timestamps where both the
    camera and the reference camera are registered."""
    pose = {}
    for im in images.values():
        camera, stamp = split_name(im["name"])
        pose[(camera, stamp)] = (quat_to_matrix(im["q"]), np.array(im["t"]))
    rigs = {c: [] for c in cameras_by_name}
    for stamp in timestamps:
        if (reference_camera, stamp) not in pose:
            continue
        R0, t0 = pose[(reference_camera, stamp)]
        for camera in cameras_by_name:
            if (camera, stamp) not in pose:
                continue
            R, t = pose[(camera, stamp)]
            # cam_from_rig = cam_from_world * world_from_rig.
            R_cr = R @ R0.T
            t_cr = t - R_cr @ t0
            rigs[camera].append((R_cr, -R_cr.T @ t_cr))
    return rigs


def split_command(args):
    cameras = read_cameras(args.map + "/cameras.txt")
    images = read_images(args.map + "/images.txt")
    points = read_points(args.map + "/points3D.txt")
    if not images:
        die("%s/images.txt has no images" % args.map)
    stamps = sorted({split_name(im["name"])[1] for im in images.values()},
                    key=lambda s: (len(s), s))
    held = {stamps[i] for i in parse_holdout(args.holdout, len(stamps))}
    if len(held) == len(stamps):
        die("the split holds out every timestamp: nothing is left for the map")
    held_ids = {iid for iid, im in images.items()
                if split_name(im["name"])[1] in held}

    # The map without the held-out images; points with < 2 map images go.
    kept_points = {}
    for pid, p in points.items():
        track = [o for o in p["track"] if o[0] not in held_ids]
        if len({o[0] for o in track}) >= 2:
            kept_points[pid] = dict(p, track=track)
    map_images = {}
    for iid, im in images.items():
        if iid in held_ids:
            continue
        obs = [(x, y, pid if pid in kept_points else -1)
               for x, y, pid in im["points2D"]]
        map_images[iid] = dict(im, points2D=obs)
    os.makedirs(args.out + "/map", exist_ok=True)
    write_model(args.out + "/map", cameras, map_images, kept_points)

    # The held-out images' observations of the remaining points.
    rows = 0
    with open(args.out + "/correspondences.txt", "w") as f:
        f.write("# rig_calibrator 2D-3D correspondences\n")
        f.write("# held out of %s (%s): %d timestamps\n"
                % (args.map, args.holdout, len(held)))
        for iid in sorted(held_ids, key=lambda i: images[i]["name"]):
            im = images[iid]
            cam = cameras[im["camera_id"]]
            lines = ["%r %r %r %r %r %d" % ((x, y) + tuple(
                kept_points[pid]["xyz"]) + (pid,))
                     for x, y, pid in im["points2D"] if pid in kept_points]
            f.write("IMAGE %s %d %d %d\n" % (im["name"], cam["width"],
                                             cam["height"], len(lines)))
            f.write("".join(l + "\n" for l in lines))
            rows += len(lines)

    # The reference: intrinsics of the map; the rig of the map's timestamps.
    names = {}
    for im in images.values():
        names.setdefault(split_name(im["name"])[0], im["camera_id"])
    camera_names = sorted(names)
    reference_camera = camera_names[0]
    map_stamps = [s for s in stamps if s not in held]
    rigs = per_timestamp_rigs(images, camera_names, reference_camera,
                              map_stamps)
    reference = {"map": args.map, "holdout": args.holdout,
                 "held_out_timestamps": len(held),
                 "map_timestamps": len(map_stamps),
                 "correspondences": rows, "reference_camera": reference_camera,
                 "cameras": {}}
    for name in camera_names:
        cam = cameras[names[name]]
        entry = {"model": cam["model"], "params": cam["params"],
                 "width": cam["width"], "height": cam["height"]}
        samples = rigs[name]
        if len(samples) >= 2:
            R_mean = mean_rotation([R for R, _ in samples])
            centres = np.array([c for _, c in samples])
            deviations = [rotation_angle_deg(R @ R_mean.T) for R, _ in samples]
            axis_dev = np.array([rotation_log(R @ R_mean.T) for R, _ in samples])
            n = len(samples)
            entry.update({
                "num_timestamps": n,
                "cam_from_rig_rotation": matrix_to_quat(R_mean).tolist(),
                "center_in_rig": centres.mean(axis=0).tolist(),
                # Per-timestamp scatter, and the standard error of the mean.
                "rotation_scatter_median_deg": float(np.median(deviations)),
                "rotation_axis_std_deg": np.degrees(
                    axis_dev.std(axis=0, ddof=1)).tolist(),
                "center_std": centres.std(axis=0, ddof=1).tolist(),
                "rotation_axis_se_deg": (np.degrees(axis_dev.std(
                    axis=0, ddof=1)) / math.sqrt(n)).tolist(),
                "center_se": (centres.std(axis=0, ddof=1) /
                              math.sqrt(n)).tolist()})
        reference["cameras"][name] = entry
    with open(args.out + "/reference.json", "w") as f:
        json.dump(reference, f, indent=1)
    print("[real_data_tools] %s: %d of %d timestamps held out (%d images, %d "
          "correspondences); map: %d images, %d points"
          % (args.holdout, len(held), len(stamps), len(held_ids), rows,
             len(map_images), len(kept_points)))


def euroc_reference_command(args):
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import euroc_tools
    sensors = [euroc_tools.read_sensor_yaml(args.sensor0),
               euroc_tools.read_sensor_yaml(args.sensor1)]
    T = [np.array(sensor["T_BS"]) for sensor in sensors]
    reference = {"map": "EuRoC sensor.yaml", "reference_camera": "cam0",
                 "cameras": {}}
    for index, sensor in enumerate(sensors):
        fx, fy, cx, cy = sensor["intrinsics"]
        entry = {"model": "OPENCV",
                 "params": [fx, fy, cx + 0.5, cy + 0.5] +
                 list(sensor["distortion_coefficients"]),
                 "width": int(sensor["resolution"][0]),
                 "height": int(sensor["resolution"][1])}
        # cam_from_cam0 = inv(T_BS_cam) * T_BS_cam0.
        cam_from_rig = np.linalg.inv(T[index]) @ T[0]
        R = cam_from_rig[:3, :3]
        entry.update({
            "num_timestamps": 0,
            "cam_from_rig_rotation": matrix_to_quat(R).tolist(),
            "center_in_rig": (-R.T @ cam_from_rig[:3, 3]).tolist(),
            "rotation_axis_se_deg": [0.0, 0.0, 0.0],
            "center_se": [0.0, 0.0, 0.0]})
        reference["cameras"]["cam%d" % index] = entry
    with open(args.out, "w") as f:
        json.dump(reference, f, indent=1)


# ---------------------------------------------------------------------------
# Comparison with the calibration's summary.

def compare_command(args):
    reference = json.load(open(args.reference))
    summary = json.load(open(args.summary))
    # The warnings and errors that name each camera.
    # The summary's diagnostics are lines "<level> <code>: <text>"; a
    # camera is named by the text ("cam1: ..." or "camera cam1: ...").
    # A warning that names no camera (e.g. "the uncertainty could not be
    # computed") flags every camera.
    flags = {}
    names = [c.get("name") for c in summary.get("cameras", [])]
    for diagnostic in summary.get("diagnostics", []):
        match = re.match(r"(\w+) (\w+): (?:camera )?([^ :]+):", diagnostic)
        if match and match.group(3) in names:
            flags.setdefault(match.group(3), []).append(match.group(2))
            continue
        match = re.match(r"(\w+) (\w+):", diagnostic)
        if match and match.group(1) in ("warning", "error"):
            for name in names:
                flags.setdefault(name, []).append(match.group(2))
    out_rows = []
    print("  %-5s %-15s %7s %7s %7s %5s | %7s %7s %7s %5s | %6s %6s %5s | %6s %6s | %s"
          % ("cam", "model", "rot_err", "rot_sig", "rot_ref", "z",
             "ctr_err", "ctr_sig", "ctr_ref", "z", "f_err%", "f_sig%", "z",
             "pp_err", "pp_sig", "verdict"))
    by_name = {c.get("name"): c for c in summary.get("cameras", [])}
    for name, ref in sorted(reference["cameras"].items()):
        cam = by_name.get(name)
        row = {"label": args.label, "camera": name,
               "flags": sorted(set(flags.get(name, [])))}
        if cam is None or not cam.get("calibrated", False):
            row.update({"calibrated": False, "verdict": "NOT CALIBRATED"})
            print("  %-5s not calibrated %s" % (name, " ".join(row["flags"])))
            out_rows.append(row)
            continue
        row["calibrated"] = True
        row["model"] = cam.get("model", "?")
        unc = cam.get("uncertainty") or {}
        R = quat_to_matrix(cam["cam_from_rig"]["rotation_wxyz"])
        centre = -R.T @ np.array(cam["cam_from_rig"]["translation"])
        is_ref = name == reference["reference_camera"]
        zs = []
        if not is_ref and "cam_from_rig_rotation" in ref:
            e = rotation_log(R @ quat_to_matrix(ref["cam_from_rig_rotation"]).T)
            sig = np.radians(np.array(
                unc.get("rotation_axis_stddev_deg") or [float("nan")] * 3,
                dtype=float))
            ref_se = np.radians(np.array(ref["rotation_axis_se_deg"]))
            # One number per camera: the norm of the per-axis error over the
            # norm of the combined per-axis sigma.
            c_err = centre - np.array(ref["center_in_rig"])
            c_sig = np.array(unc.get("center_in_rig_stddev") or
                             [float("nan")] * 3, dtype=float)
            c_ref = np.array(ref["center_se"])
            row.update({
                "rotation_error_deg": math.degrees(np.linalg.norm(e)),
                "rotation_sigma_deg": math.degrees(np.linalg.norm(sig)),
                "rotation_reference_se_deg": math.degrees(
                    np.linalg.norm(ref_se)),
                "rotation_z": float(np.linalg.norm(e) / np.linalg.norm(
                    np.sqrt(sig ** 2 + ref_se ** 2))),
                "center_error": float(np.linalg.norm(c_err)),
                "center_sigma": float(np.linalg.norm(c_sig)),
                "center_reference_se": float(np.linalg.norm(c_ref)),
                "center_z": float(np.linalg.norm(c_err) / np.linalg.norm(
                    np.sqrt(c_sig ** 2 + c_ref ** 2)))})
            zs += [row["rotation_z"], row["center_z"]]
        params = cam["params"]
        stddev = unc.get("params_stddev") or []
        f_ref = ref["params"][0]
        # The first focal length (fx, or f): every model has it first.
        row["focal_error_pct"] = 100 * (params[0] - f_ref) / f_ref
        row["focal_sigma_pct"] = (100 * stddev[0] / f_ref
                                  if stddev and stddev[0] is not None
                                  else float("nan"))
        row["focal_z"] = (abs(row["focal_error_pct"]) / row["focal_sigma_pct"]
                          if row["focal_sigma_pct"] > 0 else float("nan"))
        zs.append(row["focal_z"])
        index = summary_pp_index(row["model"])
        pp_sig = [stddev[i] if len(stddev) > i and stddev[i] is not None
                  else float("nan") for i in index]
        row["pp_error_px"] = float(np.linalg.norm(
            np.array([params[i] for i in index]) - np.array(ref["params"][2:4])))
        row["pp_sigma_px"] = float(np.linalg.norm(pp_sig))
        worst = max(zs) if zs and not any(math.isnan(z) for z in zs) \
            else float("nan")
        row["worst_z"] = worst
        if not math.isnan(worst) and worst <= 3:
            row["verdict"] = "within 3 sigma"
        elif row["flags"]:
            row["verdict"] = "flagged"
        else:
            row["verdict"] = "OFF AND SILENT"
        out_rows.append(row)
        verdict = row["verdict"] + (" (" + ", ".join(row["flags"]) + ")"
                                    if row["flags"] else "")
        if is_ref:
            print("  %-5s %-15s %7s %7s %7s %5s | %7s %7s %7s %5s | %6.3f %6.3f %5.1f | %6.2f %6.2f | %s"
                  % (name, row["model"], "rig", "", "", "", "", "", "", "",
                     row["focal_error_pct"], row["focal_sigma_pct"],
                     row["focal_z"], row["pp_error_px"], row["pp_sigma_px"],
                     verdict))
        else:
            print("  %-5s %-15s %7.3f %7.3f %7.3f %5.1f | %7.4f %7.4f %7.4f %5.1f | %6.3f %6.3f %5.1f | %6.2f %6.2f | %s"
                  % (name, row["model"], row["rotation_error_deg"],
                     row["rotation_sigma_deg"],
                     row["rotation_reference_se_deg"], row["rotation_z"],
                     row["center_error"], row["center_sigma"],
                     row["center_reference_se"], row["center_z"],
                     row["focal_error_pct"], row["focal_sigma_pct"],
                     row["focal_z"], row["pp_error_px"], row["pp_sigma_px"],
                     verdict))
    if args.table:
        with open(args.table, "a") as f:
            for row in out_rows:
                f.write(json.dumps(row) + "\n")


def verdicts_command(args):
    """The check's verdict over every row of a table: exit 1 when a camera
    is not calibrated or off without a warning naming it."""
    rows = [json.loads(line) for line in open(args.table) if line.strip()]
    bad = [r for r in rows
           if r["verdict"] in ("NOT CALIBRATED", "OFF AND SILENT")]
    counts = {}
    for r in rows:
        counts[r["verdict"]] = counts.get(r["verdict"], 0) + 1
    print("  %d cameras: %s" % (len(rows), ", ".join(
        "%d %s" % (n, v) for v, n in sorted(counts.items()))))
    zs = [r[key] for r in rows for key in ("rotation_z", "center_z")
          if key in r and not math.isnan(r[key])]
    if zs:
        print("  rotation and centre |error|/sigma (where sigma was computed): "
              "median %.2f, max %.2f, %d of %d within 3"
              % (float(np.median(zs)), max(zs), sum(z <= 3 for z in zs),
                 len(zs)))
    for r in bad:
        print("  %s %s: %s" % (r["label"], r["camera"], r["verdict"]))
    sys.exit(1 if bad else 0)


def summary_pp_index(model):
    """Indices of cx, cy in COLMAP's parameter vector of the model."""
    one_focal = {"SIMPLE_PINHOLE", "SIMPLE_RADIAL", "RADIAL",
                 "SIMPLE_RADIAL_FISHEYE", "RADIAL_FISHEYE"}
    return (1, 2) if model in one_focal else (2, 3)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("split")
    p.add_argument("map")
    p.add_argument("out")
    p.add_argument("holdout")
    p = sub.add_parser("verdicts")
    p.add_argument("table")
    p = sub.add_parser("euroc-reference")
    p.add_argument("sensor0")
    p.add_argument("sensor1")
    p.add_argument("out")
    p = sub.add_parser("compare")
    p.add_argument("reference")
    p.add_argument("summary")
    p.add_argument("--label", default="")
    p.add_argument("--table")
    args = parser.parse_args()
    {"split": split_command, "euroc-reference": euroc_reference_command,
     "compare": compare_command,
     "verdicts": verdicts_command}[args.command](args)


if __name__ == "__main__":
    main()
