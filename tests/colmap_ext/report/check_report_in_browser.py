#!/usr/bin/env python3
"""Opens report.html in headless Chromium and checks it (report_browser_test.sh).

  check_report_in_browser.py REPORT_HTML SUMMARY_JSON [--complete] [--screenshot PNG]

Fails (exit 1, every problem on stderr) if the page is not self-contained
(an external reference: src/href/url() not to the page itself or a data: URI,
<link>, <script src>, @import), is not well-formed XML, logs anything to the
browser console (the page's only script logs nothing; a script error does),
misses a section or a figure (for each calibrated camera of SUMMARY_JSON:
residuals, coverage, uncertainty, distortion; the two rig views; the
frameset errors), or if the browser drew fewer figures than the page holds
(data-rendered-figures, set by the page's script after layout, against the
<svg> count). With --complete every figure must be an <svg> and "not
computed" may not appear. --screenshot writes a PNG of the page's top.
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import xml.dom.minidom

SECTIONS = ["overview", "parameters", "intrinsics-table", "poses-table",
            "model-choice", "diagnostics", "diagnostics-list", "validity-table",
            "cameras", "rig", "framesets", "worst-framesets", "worst-images",
            "camchain"]
CAMERA_FIGURES = ["residuals", "coverage", "uncertainty", "distortion"]


def chromium():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    return None


def run_chromium(args, profile):
    # --no-sandbox: containers and CI runners as root have no user namespaces
    # for the sandbox; the page is our own file.
    command = [chromium(), "--headless=new", "--no-sandbox", "--disable-gpu",
               "--no-first-run", "--user-data-dir=" + profile,
               "--virtual-time-budget=5000"] + args
    return subprocess.run(command, capture_output=True, text=True, timeout=120)


def static_problems(html):
    problems = []
    try:
        xml.dom.minidom.parseString(html.encode("utf-8"))
    except Exception as error:  # expat errors have no common base class
        problems.append("not well-formed XML: %s" % error)
    for match in re.finditer(r'\b(src|href)\s*=\s*"([^"]*)"', html):
        if not (match.group(2).startswith("#") or
                match.group(2).startswith("data:")):
            problems.append("external reference %s=\"%s\"" % match.groups())
    for pattern in (r"<link\b", r"<script\b[^>]*\bsrc\b", r"@import",
                    r"url\(\s*['\"]?(?!#|data:)"):
        if re.search(pattern, html):
            problems.append("external resource: %s" % pattern)
    return problems


def dom_problems(dom, summary, complete):
    problems = []
    ids = set(re.findall(r'\bid="([^"]+)"', dom))
    for section in SECTIONS:
        if section not in ids:
            problems.append("section #%s missing" % section)
    figures = ["rig-above", "rig-side", "frameset-errors"]
    for index, camera in enumerate(summary["cameras"]):
        if camera.get("calibrated"):
            figures += ["%s-%d" % (name, index) for name in CAMERA_FIGURES]
    for figure in figures:
        if "fig-" + figure not in ids:
            problems.append("figure #fig-%s missing" % figure)
        elif complete and figure not in ids:
            problems.append("figure #fig-%s has no <svg id=\"%s\">" %
                            (figure, figure))
    if complete and "not computed" in dom:
        problems.append("\"not computed\" in a page that should be complete")
    body = re.search(r"<body([^>]*)>", dom)
    attributes = dict(re.findall(r'([\w-]+)="([^"]*)"', body.group(1))) \
        if body else {}
    expected = attributes.get("data-expected-figures")
    rendered = attributes.get("data-rendered-figures")
    svgs = len(re.findall(r"<figure\b[^>]*>\s*<svg\b", dom))
    if rendered is None:
        problems.append("the page's script did not run "
                        "(no data-rendered-figures)")
    elif not (rendered == expected == str(svgs)):
        problems.append("figures drawn %s, in the page %s, <svg> figures %d" %
                        (rendered, expected, svgs))
    return problems


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("report")
    parser.add_argument("summary")
    parser.add_argument("--complete", action="store_true")
    parser.add_argument("--screenshot")
    args = parser.parse_args()
    if chromium() is None:
        print("chromium not found (scripts/setup_deps.sh installs it)",
              file=sys.stderr)
        return 2
    with open(args.report, encoding="utf-8") as file:
        html = file.read()
    with open(args.summary, encoding="utf-8") as file:
        summary = json.load(file)
    problems = static_problems(html)
    url = "file://" + os.path.abspath(args.report)
    with tempfile.TemporaryDirectory() as profile:
        result = run_chromium(["--enable-logging=stderr", "--v=0",
                               "--dump-dom", url], profile)
        if result.returncode != 0 or "<html" not in result.stdout:
            problems.append("chromium failed (exit %d): %s" %
                            (result.returncode, result.stderr[-2000:]))
        console = [line for line in result.stderr.splitlines()
                   if ":CONSOLE" in line]
        problems += ["console: " + line for line in console]
        problems += dom_problems(result.stdout, summary, args.complete)
        if args.screenshot:
            shot = run_chromium(["--hide-scrollbars", "--window-size=1280,2400",
                                 "--screenshot=" + args.screenshot, url],
                                profile)
            if shot.returncode != 0 or not os.path.isfile(args.screenshot):
                problems.append("no screenshot: " + shot.stderr[-2000:])
    for problem in problems:
        print("report check: " + problem, file=sys.stderr)
    print("report check of %s: %s" % (args.report, "FAILED" if problems
                                      else "passed"))
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
