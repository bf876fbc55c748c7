#!/usr/bin/env bash
# check_report_html.sh REPORT_DIR [SCREENSHOT.png]
#
# Opens REPORT_DIR/report.html in headless Chromium (from file://) and checks the DOM the browser
# built: every data-plot named in the file must have a <figure class="plot"> holding an <svg> with
# drawn content (<path>, <polyline>, <polygon> or <line>), and no "plot missing" placeholder.
# With SCREENSHOT.png it also saves a 1280×2400 screenshot.
# Exit 0 ok, 1 failed, 2 bad usage, 77 skipped (no chromium, or no gnuplot to draw the plots).
set -u
if [[ $# -lt 1 || $# -gt 2 ]]; then
  echo "usage: $0 REPORT_DIR [SCREENSHOT.png]" >&2
  exit 2
fi
dir=$1
shot=${2:-}
html=$dir/report.html
py=/usr/bin/python3
if [[ ! -f $html ]]; then
  echo "FAIL: $html does not exist" >&2
  exit 1
fi
browser=""
for b in chromium chromium-browser google-chrome; do
  if command -v "$b" >/dev/null 2>&1; then browser=$(command -v "$b"); break; fi
done
if [[ -z $browser ]]; then
  echo "skipped: chromium is not installed (Debian: apt-get install chromium)"
  exit 77
fi
if [[ ! -x $py ]]; then
  echo "skipped: $py is needed to read the DOM"
  exit 77
fi
if grep -q 'class="plot missing"' "$html" && ! command -v gnuplot >/dev/null 2>&1; then
  echo "skipped: gnuplot is not installed, so the report has placeholders instead of plots (Debian: apt-get install gnuplot-nox)"
  exit 77
fi

work=$(mktemp -d "${TMPDIR:-/tmp}/mechbench-chromium-XXXXXX")
trap 'rm -rf "$work"' EXIT
url=$("$py" -c 'import pathlib, sys; print(pathlib.Path(sys.argv[1]).resolve().as_uri())' "$html")
flags=(--headless --no-sandbox --disable-gpu --user-data-dir="$work/profile" --no-first-run
       --disable-extensions --disable-background-networking --disable-dev-shm-usage)

if ! timeout -k 5 20 "$browser" "${flags[@]}" --dump-dom "$url" >"$work/dom.html" 2>"$work/chromium.log"; then
  echo "FAIL: $browser --dump-dom $url did not finish within 20 s or failed; its log:" >&2
  tail -n 20 "$work/chromium.log" >&2
  exit 1
fi
if [[ -n $shot ]]; then
  mkdir -p "$(dirname "$shot")"
  if ! timeout -k 5 20 "$browser" "${flags[@]}" --hide-scrollbars --window-size=1280,2400 \
      --screenshot="$(realpath -m "$shot")" "$url" >"$work/shot.log" 2>&1 || [[ ! -s $shot ]]; then
    echo "FAIL: no screenshot written to $shot; chromium's log:" >&2
    tail -n 20 "$work/shot.log" >&2
    exit 1
  fi
  echo "screenshot: $shot"
fi

"$py" - "$html" "$work/dom.html" <<'PY'
import re
import sys
from html.parser import HTMLParser

source = open(sys.argv[1], encoding="utf-8").read()
dom = open(sys.argv[2], encoding="utf-8").read()
expected = re.findall(r'data-plot="([^"]*)"', source)


class Figures(HTMLParser):
    """Collects, per <figure data-plot>, its classes and whether an <svg> inside it draws."""
    DRAWN = {"path", "polyline", "polygon", "line"}

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.figures = []      # (data-plot, classes, has_svg, drawn)
        self.current = None

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "figure":
            self.current = [a.get("data-plot"), (a.get("class") or "").split(), False, 0]
        elif self.current is not None:
            if tag == "svg":
                self.current[2] = True
            elif tag in self.DRAWN and self.current[2]:
                self.current[3] += 1

    def handle_startendtag(self, tag, attrs):
        self.handle_starttag(tag, attrs)

    def handle_endtag(self, tag):
        if tag == "figure" and self.current is not None:
            self.figures.append(tuple(self.current))
            self.current = None


p = Figures()
p.feed(dom)
problems = []
if not dom.strip():
    problems.append("the browser returned an empty DOM")
if not expected:
    problems.append("the page names no plots (no data-plot attribute)")
for name in expected:
    figs = [f for f in p.figures if f[0] == name]
    ok = [f for f in figs if "plot" in f[1] and "missing" not in f[1] and f[2] and f[3] > 0]
    if not figs:
        problems.append(f"{name}: no <figure> with this data-plot in the rendered DOM")
    elif not ok:
        f = figs[0]
        why = ("it is a 'plot missing' placeholder" if "missing" in f[1]
               else "it holds no <svg>" if not f[2] else "its <svg> draws nothing")
        problems.append(f"{name}: {why}")
if "plot missing" in dom:
    problems.append("the rendered page has a 'plot missing' placeholder")
drawn = sum(1 for f in p.figures if "plot" in f[1] and f[2] and f[3] > 0)
if problems:
    for line in problems:
        print("FAIL:", line, file=sys.stderr)
    sys.exit(1)
print(f"ok: {drawn} plot(s) drawn in the browser's DOM for {len(expected)} data-plot(s): {', '.join(expected)}")
PY
