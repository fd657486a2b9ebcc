#!/usr/bin/env bash
# layout.sh FACETFIT: the report as a person sees it, in headless Chromium at 1400 x 900 pixels: no
# horizontal scroll (the page no wider than the window), the Delta E maps' colour scale and the run-time
# plot's legend present. Writes the screenshot beside the report (kept on failure). Skips (77) without
# Chromium (scripts/deps-debian.txt installs it).
set -euo pipefail
facetfit=$1
browser=$(command -v chromium || command -v chromium-browser || true)
[[ -n $browser ]] || { echo "no Chromium: skipped"; exit 77; }
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
"$facetfit" -q report builtin: -o "$tmp/report" --size 16 --spp 2 >/dev/null
# A page beside the report that measures it in a 1400-pixel frame (file pages may read each other only
# with --allow-file-access-from-files).
cat >"$tmp/report/measure.html" <<'HTML'
<!doctype html><html><body style="margin:0"><iframe id="f" src="index.html" style="width:1400px;height:900px;border:0"></iframe>
<pre id="out">not loaded</pre><script>
document.getElementById('f').onload = () => {
  const d = document.getElementById('f').contentDocument, e = d.documentElement;
  const legend = [...d.querySelectorAll('svg text[fill]')].map(t => t.textContent.trim()).join(',');
  document.getElementById('out').textContent = 'scroll ' + e.scrollWidth + ' client ' + e.clientWidth +
    ' scale ' + d.querySelectorAll('svg.heatmap-scale').length + ' legend ' + legend + ' end';
};
</script></body></html>
HTML
flags=(--headless=new --no-sandbox --disable-gpu --allow-file-access-from-files --virtual-time-budget=10000)
line=$(timeout 120 "$browser" "${flags[@]}" --window-size=1420,1000 --dump-dom "file://$tmp/report/measure.html" 2>/dev/null |
       grep -o 'scroll [0-9]* client [0-9]* scale [0-9]* legend [^<]* end' || true)
timeout 120 "$browser" "${flags[@]}" --window-size=1400,900 --screenshot="$tmp/report/screenshot.png" "file://$tmp/report/index.html" \
  >/dev/null 2>&1 || true
echo "${line:-no measurement}"
read -r _ scroll _ client _ scale _ <<<"${line:-x 0 x 1 x 0}"
legend=$(sed 's/.* legend \(.*\) end/\1/' <<<"$line")
status=0
(( scroll <= client )) || { echo "FAIL: the page is $scroll pixels wide in a $client-pixel window (horizontal scroll)"; status=1; }
(( scale >= 1 )) || { echo "FAIL: no colour scale beside the Delta E maps"; status=1; }
for r in tabulated ggx beckmann lsq closures; do
  [[ $legend == *"$r"* ]] || { echo "FAIL: the run-time plot's legend lacks $r"; status=1; }
done
if (( status )); then keep=$(mktemp -d); cp -r "$tmp/report" "$keep/"; echo "report and screenshot kept in $keep/report"; fi
exit $status
