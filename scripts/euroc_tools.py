#!/usr/bin/env python3
"""Small helpers of scripts/euroc_check.sh (standard library only).

  reference SENSOR0_YAML SENSOR1_YAML OUT_CAMCHAIN
      The EuRoC reference calibration as a Kalibr camchain.yaml, which
      `rig_calibrator evaluate` reads. EuRoC's sensor.yaml is already in
      Kalibr's convention (pinhole, radial-tangential = COLMAP OPENCV; the
      center of the top-left pixel at (0, 0)), so the intrinsics are copied
      unchanged and the reader adds 0.5 to the principal point (COLMAP puts
      that pixel center at (0.5, 0.5)). T_BS is body_from_sensor, so
      T_cn_cnm1 = cam1_from_cam0 = inv(T_BS1) * T_BS0.
  pairs FRAMES OUT_PAIRS
      COLMAP match list for the map: every frameset's stereo pair, all
      camera combinations of the next two framesets, and the first and last
      frameset's cam0 images (the rig's motion over the map's time).
  parallax DATABASE
      Image motion in the map database's verified matches: median match
      displacement of the cam0-cam0 pairs (motion of the rig) and of the
      same-frameset cam0-cam1 pairs (stereo disparity), and COLMAP's
      two-view configuration of each kind.
  scale MODEL_TXT BASELINE_M OUT_TRANSFORM
      Distance between map_cam0/X and map_cam1/X in the map (text model) for
      every map frameset; writes the 4x4 similarity diag(s, s, s, 1) with
      s = BASELINE_M / median distance for `colmap model_transformer`.
  rig CAMCHAIN
      Baseline (norm of cam1_from_cam0's translation) and relative rotation
      angle of a camchain.yaml.
"""
import math
import re
import sqlite3
import statistics
import struct
import sys


def die(message):
    sys.stderr.write("[euroc_tools] ERROR: %s\n" % message)
    sys.exit(1)


def numbers(text):
    return [float(x) for x in re.findall(r"[-+]?\d*\.?\d+(?:[eE][-+]?\d+)?", text)]


def read_sensor_yaml(path):
    try:
        text = open(path).read()
    except OSError as e:
        die("cannot read %s: %s" % (path, e))
    sensor = {}
    match = re.search(r"T_BS:.*?data:\s*\[(.*?)\]", text, re.S)
    if not match or len(numbers(match.group(1))) != 16:
        die("%s: no 4x4 T_BS data" % path)
    values = numbers(match.group(1))
    sensor["T_BS"] = [values[4 * r:4 * r + 4] for r in range(4)]
    for key, count in (("intrinsics", 4), ("distortion_coefficients", 4),
                       ("resolution", 2)):
        match = re.search(r"^%s:\s*\[(.*?)\]" % key, text, re.M | re.S)
        if not match or len(numbers(match.group(1))) != count:
            die("%s: %s needs %d numbers" % (path, key, count))
        sensor[key] = numbers(match.group(1))
    for key, value in (("camera_model", "pinhole"),
                       ("distortion_model", "radial-tangential")):
        if not re.search(r"^%s:\s*%s\s*$" % (key, value), text, re.M):
            die("%s: expected %s: %s" % (path, key, value))
    return sensor


def rigid_inverse(T):
    R = [row[:3] for row in T[:3]]
    t = [row[3] for row in T[:3]]
    Rt = [[R[c][r] for c in range(3)] for r in range(3)]
    ti = [-sum(Rt[r][c] * t[c] for c in range(3)) for r in range(3)]
    return [Rt[r] + [ti[r]] for r in range(3)] + [[0.0, 0.0, 0.0, 1.0]]


def matmul(A, B):
    return [[sum(A[r][k] * B[k][c] for k in range(4)) for c in range(4)]
            for r in range(4)]


def rotation_angle_deg(T):
    trace = T[0][0] + T[1][1] + T[2][2]
    return math.degrees(math.acos(max(-1.0, min(1.0, (trace - 1) / 2))))


def reference(sensor0_path, sensor1_path, out_path):
    sensors = [read_sensor_yaml(sensor0_path), read_sensor_yaml(sensor1_path)]
    cam1_from_cam0 = matmul(rigid_inverse(sensors[1]["T_BS"]),
                            sensors[0]["T_BS"])
    lines = ["# EuRoC reference calibration (sensor.yaml of cam0, cam1), "
             "Kalibr convention:",
             "# integer pixel centers; T_cn_cnm1 = cam1_from_cam0 = "
             "inv(T_BS1) * T_BS0."]
    for index, sensor in enumerate(sensors):
        lines.append("cam%d:" % index)
        if index == 1:
            lines.append("  T_cn_cnm1:")
            lines += ["  - [%s]" % ", ".join("%.12g" % v for v in row)
                      for row in cam1_from_cam0]
        lines += [
            "  camera_model: pinhole",
            "  intrinsics: [%s]" % ", ".join("%.12g" % v
                                             for v in sensor["intrinsics"]),
            "  distortion_model: radtan",
            "  distortion_coeffs: [%s]" % ", ".join(
                "%.12g" % v for v in sensor["distortion_coefficients"]),
            "  resolution: [%d, %d]" % tuple(sensor["resolution"]),
        ]
    with open(out_path, "w") as f:
        f.write("\n".join(lines) + "\n")
    t = [row[3] for row in cam1_from_cam0[:3]]
    print("reference baseline %.5f m, relative rotation %.3f deg" %
          (math.sqrt(sum(v * v for v in t)), rotation_angle_deg(cam1_from_cam0)))


def pairs(frames_path, out_path):
    frames = [line.strip() for line in open(frames_path) if line.strip()]
    cameras = ("map_cam0", "map_cam1")
    result = []
    for i, frame in enumerate(frames):
        result.append(("map_cam0/" + frame, "map_cam1/" + frame))
        for j in (i + 1, i + 2):
            if j < len(frames):
                result += [(a + "/" + frame, b + "/" + frames[j])
                           for a in cameras for b in cameras]
    if len(frames) > 3:
        result.append(("map_cam0/" + frames[0], "map_cam0/" + frames[-1]))
    with open(out_path, "w") as f:
        f.writelines("%s %s\n" % p for p in result)
    print("%d image pairs to match" % len(result))


TWO_VIEW_CONFIG = {0: "undefined", 1: "degenerate", 2: "calibrated",
                   3: "uncalibrated", 4: "planar", 5: "panoramic",
                   6: "planar or panoramic", 7: "watermark", 8: "multiple"}


def parallax(database_path):
    db = sqlite3.connect("file:%s?mode=ro" % database_path, uri=True)
    keypoints = {}
    for image_id, rows, cols, data in db.execute(
            "SELECT image_id, rows, cols, data FROM keypoints"):
        values = struct.unpack("%df" % (rows * cols), data)
        keypoints[image_id] = [values[i * cols:i * cols + 2]
                               for i in range(rows)]
    names = dict(db.execute("SELECT image_id, name FROM images"))
    kinds = {"cam0-cam0 (rig motion)": [],
             "cam0-cam1, same frameset (stereo)": []}
    for pair_id, rows, cols, data, config in db.execute(
            "SELECT pair_id, rows, cols, data, config FROM two_view_geometries"
            " WHERE rows > 0"):
        id2 = pair_id % 2147483647
        id1 = (pair_id - id2) // 2147483647
        (camera1, frame1), (camera2, frame2) = (names[id1].split("/"),
                                                names[id2].split("/"))
        if camera1 == camera2 == "map_cam0":
            kind = "cam0-cam0 (rig motion)"
        elif frame1 == frame2 and camera1 != camera2:
            kind = "cam0-cam1, same frameset (stereo)"
        else:
            continue
        matches = struct.unpack("%dI" % (rows * cols), data)
        shifts = [math.dist(keypoints[id1][matches[2 * k]],
                            keypoints[id2][matches[2 * k + 1]])
                  for k in range(rows)]
        shifts.sort()
        kinds[kind].append((statistics.median(shifts),
                            shifts[int(0.9 * (len(shifts) - 1))], config))
    for kind, found in kinds.items():
        if not found:
            print("  %s: no verified pairs" % kind)
            continue
        configs = {}
        for _, _, config in found:
            name = TWO_VIEW_CONFIG.get(config, str(config))
            configs[name] = configs.get(name, 0) + 1
        print("  %s: %d pairs; median match displacement per pair %.2f px "
              "(range %.2f-%.2f), 90th percentile at most %.2f px; "
              "COLMAP two-view geometry: %s" %
              (kind, len(found), statistics.median(f[0] for f in found),
               min(f[0] for f in found), max(f[0] for f in found),
               max(f[1] for f in found),
               ", ".join("%s %d" % item for item in sorted(configs.items()))))


def quaternion_to_rotation(w, x, y, z):
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]]


def scale(model_path, baseline, out_path):
    centers = {}
    with open(model_path + "/images.txt") as f:
        lines = [line for line in f if not line.startswith("#")]
    for line in lines[0::2]:
        fields = line.split()
        if len(fields) < 10:
            continue
        q = [float(v) for v in fields[1:5]]
        t = [float(v) for v in fields[5:8]]
        R = quaternion_to_rotation(*q)
        centers[fields[9]] = [-sum(R[r][c] * t[r] for r in range(3))
                              for c in range(3)]
    distances = []
    for name, center in centers.items():
        camera, frame = name.split("/", 1)
        if camera == "map_cam0" and "map_cam1/" + frame in centers:
            distances.append(math.dist(center, centers["map_cam1/" + frame]))
    if len(distances) < 1:
        die("no frameset with both map_cam0 and map_cam1 in the map %s" %
            model_path)
    median = statistics.median(distances)
    if not median > 0:
        die("the map's stereo baseline is zero")
    s = baseline / median
    spread = (max(distances) - min(distances)) / median * 100
    with open(out_path, "w") as f:
        for r in range(4):
            f.write(" ".join("%.15g" % (s if r == c and r < 3 else
                                        (1.0 if r == c else 0.0))
                             for c in range(4)) + "\n")
    print("stereo baseline in the map over %d framesets: median %.6g map "
          "units (spread %.2f %% of it); scale %.6g m per map unit" %
          (len(distances), median, spread, s))


def rig(camchain_path):
    text = open(camchain_path).read()
    match = re.search(r"cam1:.*?T_cn_cnm1:\s*((?:\s*-\s*\[[^\]]*\]){4})",
                      text, re.S)
    if not match:
        die("%s: no cam1 T_cn_cnm1" % camchain_path)
    values = numbers(match.group(1))
    T = [values[4 * r:4 * r + 4] for r in range(4)]
    t = [row[3] for row in T[:3]]
    print("baseline %.6f m (t = %.5f %.5f %.5f), relative rotation %.3f deg" %
          (math.sqrt(sum(v * v for v in t)), t[0], t[1], t[2],
           rotation_angle_deg(T)))


def main(argv):
    commands = {"reference": (reference, 3), "pairs": (pairs, 2),
                "parallax": (parallax, 1), "rig": (rig, 1),
                "scale": (lambda m, b, o: scale(m, float(b), o), 3)}
    if len(argv) < 2 or argv[1] not in commands or \
            len(argv) - 2 != commands[argv[1]][1]:
        sys.stderr.write(__doc__)
        return 2
    commands[argv[1]][0](*argv[2:])
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
