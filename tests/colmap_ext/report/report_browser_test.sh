#!/usr/bin/env bash
# The report in a real browser (ctest report_browser): a synthetic
# calibration writes report.html; headless Chromium opens it, as written and
# with every key of issue 12's contract merged into the summary and the page
# rebuilt by `rig_calibrator report` (check_report_in_browser.py: no console
# message, every section and figure present and drawn, self-contained); two
# broken pages (a script error, a missing figure) must fail the same check.
# The screenshot of the complete page is kept in the build tree.
#   bash report_browser_test.sh BUILD_DIR
# Without chromium: an error, or a skip (exit 77) when RIG_CALIBRATOR_SKIP_APT=1
# says the set-up did not install packages.
set -euo pipefail

build="$(cd "$1" && pwd)"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
check="$here/check_report_in_browser.py"
rig_calibrator="$build/rig_calibrator"
rig_calibrator_lab="$build/rig_calibrator_lab"
work="$build/report_browser_test"
rm -rf "$work"
mkdir -p "$work"

if ! command -v chromium >/dev/null 2>&1; then
  if [ "${RIG_CALIBRATOR_SKIP_APT:-0}" = 1 ]; then
    echo "SKIPPED: chromium is not installed and RIG_CALIBRATOR_SKIP_APT=1 (install Debian's chromium)"
    exit 77
  fi
  echo "FAILED: chromium not found: run scripts/setup_deps.sh (it installs Debian's chromium)" >&2
  exit 1
fi

"$rig_calibrator_lab" synthetic --preset fisheye_helmet5 --num_framesets 12 \
  --output_path "$work/data" > "$work/synthetic.log"
models="$(grep -o 'camera_model [^ ]*' "$work/synthetic.log" | cut -d' ' -f2)"
"$rig_calibrator" --correspondences_path "$work/data/correspondences.txt" \
  --output_path "$work/calibration" --RigCalibrator.camera_model "$models" \
  --RigCalibrator.refine_points 0 > "$work/calibration.log"
[ -f "$work/calibration/report.html" ] || { echo "FAILED: the calibration wrote no report.html" >&2; exit 1; }

echo "== the report as the calibration wrote it"
python3 "$check" "$work/calibration/report.html" "$work/calibration/calibration_summary.json"

echo "== every contract key (contract_keys.json) merged, rebuilt by rig_calibrator report"
cp -r "$work/calibration" "$work/complete"
python3 - "$here/contract_keys.json" "$work/complete/calibration_summary.json" <<'PY'
import json, sys
fixture = json.load(open(sys.argv[1]))
summary = json.load(open(sys.argv[2]))
summary["uncertainty_method"] = fixture["uncertainty_method"]
summary["diagnostics"] += fixture["diagnostics"]
for camera in summary["cameras"]:
    camera.update(fixture["camera_keys"])
    camera["uncertainty"] = dict(fixture["camera_keys"]["uncertainty"],
        params_stddev=fixture["params_stddev_by_model"][camera["model"]])
json.dump(summary, open(sys.argv[2], "w"), indent=2)
PY
"$rig_calibrator" report --calibration_path "$work/complete"
python3 "$check" "$work/complete/report.html" "$work/complete/calibration_summary.json" \
  --complete --screenshot "$work/report_screenshot.png"
echo "Screenshot of the complete report: $work/report_screenshot.png"
echo "Report size: $(wc -c < "$work/complete/report.html") bytes (5 cameras, 12 framesets)"

echo "== broken pages must fail the check"
python3 - "$work/complete/report.html" "$work" <<'PY'
import re, sys
html = open(sys.argv[1]).read()
open(sys.argv[2] + "/broken_script.html", "w").write(
    html.replace("</body>", "<script>undefinedFunction();</script></body>"))
open(sys.argv[2] + "/broken_figure.html", "w").write(
    re.sub(r'<figure id="fig-rig-side">.*?</figure>', "", html, flags=re.S))
PY
for broken in broken_script broken_figure; do
  if python3 "$check" "$work/$broken.html" "$work/complete/calibration_summary.json" \
       --complete 2> "$work/$broken.log"; then
    echo "FAILED: the check passed $broken.html" >&2
    exit 1
  fi
  echo "$broken.html fails as it must: $(grep -m1 'report check:' "$work/$broken.log")"
done
echo "PASSED"
