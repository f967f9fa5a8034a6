#!/usr/bin/env bash
# Renders a sample diagnosis report in headless Chromium and checks that every plot drew.
# Usage: report_render_test.sh <write_sample_report executable>
#
# The report itself carries no JavaScript. The test therefore works on two copies:
#  1. the untouched page: it must contain no script, and a screenshot of it must hold far more
#     ink than a screenshot of an empty page;
#  2. a copy with a probe script appended: for every <svg class="plot"> the probe reports the
#     laid-out size, the number of drawn child elements with a non-empty bounding box, and the
#     result of rasterising that SVG alone onto a canvas (pixels that are not white, saturated
#     pixels of heat-map cells, distinct colours, and the ink of each line series drawn alone). Chromium's --dump-dom prints the probe's verdict.
# Chromium missing is a failure, not a skip: CI installs it (tools/setup-debian.sh).
set -euo pipefail

fail() {
  echo "report_renders_in_chromium: FAIL: $*" >&2
  exit 1
}

[ $# -eq 1 ] || fail "usage: $0 <write_sample_report>"
generator=$1
[ -x "$generator" ] || fail "generator $generator is not executable"

browser=""
for candidate in chromium chromium-browser google-chrome; do
  if command -v "$candidate" >/dev/null 2>&1; then
    browser=$(command -v "$candidate")
    break
  fi
done
[ -n "$browser" ] || fail "chromium is not installed; install it with 'apt-get install -y chromium' (tools/setup-debian.sh does)"

work=$(mktemp -d "${TMPDIR:-/tmp}/pliant-report-render.XXXXXX")
trap 'rm -rf "$work"' EXIT

# Headless, as root, without a desktop session; profile and crash data stay in $work.
chrome() {
  timeout 25 "$browser" --headless --disable-gpu --no-sandbox --no-first-run \
    --no-default-browser-check --disable-extensions --disable-background-networking \
    --disable-component-update --disable-sync --mute-audio --hide-scrollbars \
    --disable-dev-shm-usage --user-data-dir="$work/profile" --crash-dumps-dir="$work/crash" \
    "$@" 2>>"$work/chromium.log"
}

"$generator" "$work/report" || fail "write_sample_report failed"
page="$work/report/index.html"
[ -s "$page" ] || fail "no index.html written"

# --- 1. the page as shipped ----------------------------------------------------------------
if grep -qi '<script' "$page"; then fail "the report contains a <script> element"; fi
mapfile -t expected < <(grep -o 'data-plot="[^"]*"' "$page" | sed 's/^data-plot="//; s/"$//')
[ ${#expected[@]} -ge 3 ] || fail "expected at least 3 plots in the page, found ${#expected[@]}"
printf '%s\n' "${expected[@]}" | grep -qx residual_before || fail "no residual_before plot"
printf '%s\n' "${expected[@]}" | grep -qx residual_after || fail "no residual_after plot"
printf '%s\n' "${expected[@]}" | grep -q '^trajectory_' || fail "no trajectory plot"

echo '<!DOCTYPE html><html><body></body></html>' >"$work/blank.html"
chrome --window-size=1280,2400 --screenshot="$work/blank.png" "file://$work/blank.html" >/dev/null ||
  fail "chromium could not take a screenshot (log: $(tail -n 3 "$work/chromium.log" | tr '\n' ' '))"
chrome --window-size=1280,2400 --screenshot="$work/page.png" "file://$page" >/dev/null ||
  fail "chromium could not take a screenshot of the report"
blank_bytes=$(stat -c %s "$work/blank.png")
page_bytes=$(stat -c %s "$work/page.png")
echo "screenshot: report ${page_bytes} bytes, empty page ${blank_bytes} bytes"
[ "$page_bytes" -gt $((blank_bytes * 5)) ] && [ "$page_bytes" -gt 30000 ] ||
  fail "the report screenshot looks blank (${page_bytes} bytes vs ${blank_bytes} for an empty page)"

# --- 2. a probed copy ----------------------------------------------------------------------
probed="$work/report/probed.html"
sed 's#</body>##; s#</html>##' "$page" >"$probed"
cat >>"$probed" <<'EOF'
<pre id="render-probe">PROBE-PENDING</pre>
<script>
(async () => {
  const out = [];
  const near = (d, i, rgb, tol) =>
    Math.abs(d[i] - rgb[0]) <= tol && Math.abs(d[i + 1] - rgb[1]) <= tol && Math.abs(d[i + 2] - rgb[2]) <= tol;
  // Rasterises an SVG element on its own (as an image on a white canvas); returns RGBA bytes.
  const raster = async (node, w, h, what) => {
    const img = new Image();
    await new Promise((resolve, reject) => {
      img.onload = resolve;
      img.onerror = () => reject(new Error(what + ' does not load as an SVG image'));
      img.src = 'data:image/svg+xml;charset=utf-8,' + encodeURIComponent(new XMLSerializer().serializeToString(node));
    });
    const canvas = document.createElement('canvas');
    canvas.width = w; canvas.height = h;
    const g = canvas.getContext('2d');
    g.fillStyle = '#ffffff'; g.fillRect(0, 0, w, h);
    g.drawImage(img, 0, 0, w, h);
    return g.getImageData(0, 0, w, h).data;
  };
  const inkOf = (d) => {
    let n = 0;
    for (let i = 0; i < d.length; i += 4) if (d[i] < 245 || d[i + 1] < 245 || d[i + 2] < 245) n++;
    return n;
  };
  for (const svg of document.querySelectorAll('svg.plot')) {
    const name = svg.getAttribute('data-plot');
    const box = svg.getBoundingClientRect();
    const style = getComputedStyle(svg);
    const visible = style.display !== 'none' && style.visibility !== 'hidden' && box.width > 0 && box.height > 0;
    let drawn = 0;
    for (const el of svg.querySelectorAll('path, rect, polyline, line, text')) {
      if (el.closest('defs')) continue;
      const b = el.getBBox();
      if (b.width > 0 || b.height > 0) drawn++;
    }
    const title = svg.querySelector(':scope > title');
    const hasTitle = title !== null && title.textContent.length > 0;
    const w = Math.ceil(svg.viewBox.baseVal.width), h = Math.ceil(svg.viewBox.baseVal.height);
    const d = await raster(svg, w, h, 'plot ' + name);
    let saturated = 0;
    const colours = new Set();
    for (let i = 0; i < d.length; i += 4) {
      // heat-map cells are saturated colours; the hatch, text and axes are grey or black
      if (Math.max(d[i], d[i + 1], d[i + 2]) - Math.min(d[i], d[i + 1], d[i + 2]) > 40 && !near(d, i, [214, 39, 40], 40)) saturated++;
      colours.add((d[i] >> 3) << 10 | (d[i + 1] >> 3) << 5 | (d[i + 2] >> 3));
    }
    // Each line series alone: a copy of the plot without the white background keeping only the
    // polylines of one stroke colour must still put ink on the canvas.
    const series = {observed: '#111111', baseline: '#e6550d', augmented: '#3182bd'};
    const lineInk = [];
    for (const [label, stroke] of Object.entries(series)) {
      const copy = svg.cloneNode(true);
      for (const el of Array.from(copy.children)) {
        if (el.tagName === 'title') continue;
        if (el.tagName !== 'polyline' || el.getAttribute('stroke') !== stroke) el.remove();
      }
      lineInk.push(label + '=' + inkOf(await raster(copy, w, h, 'plot ' + name + ' ' + label)));
    }
    out.push(['PLOT', name, 'visible=' + (visible ? 1 : 0), 'title=' + (hasTitle ? 1 : 0),
              'drawn=' + drawn, 'pixels=' + w * h, 'inked=' + inkOf(d), 'saturated=' + saturated,
              'colours=' + colours.size].concat(lineInk).join(' '));
  }
  out.push('PROBE-DONE');
  document.getElementById('render-probe').textContent = out.join('\n');
})().catch(e => { document.getElementById('render-probe').textContent = 'PROBE-ERROR ' + e.message; });
</script>
</body></html>
EOF
chrome --window-size=1280,2400 --virtual-time-budget=15000 --dump-dom "file://$probed" >"$work/dom.html" ||
  fail "chromium --dump-dom failed (log: $(tail -n 3 "$work/chromium.log" | tr '\n' ' '))"
probe=$(sed -n '/<pre id="render-probe">/,/<\/pre>/p' "$work/dom.html")
grep -q 'PROBE-ERROR' <<<"$probe" && fail "$(grep -o 'PROBE-ERROR.*' <<<"$probe")"
grep -q 'PROBE-DONE' <<<"$probe" || fail "the probe did not finish; dumped DOM has: $(head -c 300 <<<"$probe")"

field() { grep -o " $1=[0-9]*" <<<"$2" | cut -d= -f2; }
failures=0
for name in "${expected[@]}"; do
  line=$(grep "^PLOT $name " <<<"$probe" || grep "PLOT $name " <<<"$probe" || true)
  if [ -z "$line" ]; then
    echo "plot $name: not in the rendered DOM" >&2
    failures=$((failures + 1))
    continue
  fi
  line=${line#*PLOT }
  visible=$(field visible "$line"); title=$(field title "$line"); drawn=$(field drawn "$line")
  pixels=$(field pixels "$line"); inked=$(field inked "$line"); colours=$(field colours "$line")
  problems=()
  [ "$visible" = 1 ] || problems+=("not laid out")
  [ "$title" = 1 ] || problems+=("no title")
  [ "$drawn" -ge 10 ] || problems+=("only $drawn drawn elements")
  [ $((inked * 100)) -ge $((pixels * 3)) ] || problems+=("only $inked of $pixels pixels inked")
  case $name in
    residual_*)
      # The sample's maps are observed almost everywhere: their cells must cover at least a
      # fifth of the plot in saturated (viridis) colours, in many distinct shades.
      saturated=$(field saturated "$line")
      [ $((saturated * 5)) -ge "$pixels" ] || problems+=("only $saturated saturated pixels: heat map cells missing")
      [ "$colours" -ge 12 ] || problems+=("only $colours colours") ;;
    trajectory_*)
      [ "$(field observed "$line")" -ge 100 ] || problems+=("observed line not drawn")
      [ "$(field baseline "$line")" -ge 100 ] || problems+=("baseline line not drawn")
      [ "$(field augmented "$line")" -ge 100 ] || problems+=("augmented line not drawn") ;;
  esac
  if [ ${#problems[@]} -gt 0 ]; then
    echo "plot $name: $(IFS=';'; echo "${problems[*]}") [$line]" >&2
    failures=$((failures + 1))
  else
    echo "plot $name rendered: $line"
  fi
done
[ "$failures" -eq 0 ] || fail "$failures of ${#expected[@]} plots did not render"
echo "report_renders_in_chromium: all ${#expected[@]} plots rendered"
