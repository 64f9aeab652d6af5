// ctest report_markers: a results folder's report.html in Debian's Chromium,
// headless, driven by puppeteer-core. Every crossing with ground control
// (report.json "crossings", role control or check) must have its marker in
// the ground-control plot, and every matched crossing its marker in the
// trajectory map, each inside its plot's frame and visible there: the clip
// path the page resolves for the marker's group is its own plot's and holds
// the marker, and the browser's hit test at the marker's centre finds the
// marker's own plot group (a marker clipped away is not hit). Ids must be unique in the page (issue 47: one shared clip-path id
// hid the control at one end of the demo survey).
// With SCREENSHOT_DIR, writes small PNGs of the report's main figures.
// Usage: node check_report.mjs RESULTS_FOLDER [SCREENSHOT_DIR]
import { readFileSync, mkdirSync } from 'node:fs';
import puppeteer from 'puppeteer-core';

const [results, shots] = process.argv.slice(2);
const report = JSON.parse(readFileSync(`${results}/report.json`, 'utf8'));
const controlled = report.crossings
  .filter((c) => c.role === 'control' || c.role === 'check')
  .map((c) => c.crossing_id);
const matched = report.crossings
  .filter((c) => c.matched_exposures > 0).map((c) => c.crossing_id);
let failures = 0;
const fail = (message) => { console.error('FAIL: ' + message); ++failures; };
if (controlled.length === 0) fail('report.json has no control or check crossing');

const browser = await puppeteer.launch({
  executablePath: '/usr/bin/chromium',
  headless: true,
  args: ['--no-sandbox', '--disable-gpu', '--disable-background-networking',
         '--disable-component-update', '--no-first-run', '--disable-sync',
         '--disable-quic'],
});
try {
  const page = await browser.newPage();
  await page.setViewport({ width: 1150, height: 900 });
  await page.goto(`file://${results}/report.html`, { waitUntil: 'load' });

  const duplicates = await page.evaluate(() => {
    const seen = new Map();
    for (const e of document.querySelectorAll('[id]')) {
      seen.set(e.id, (seen.get(e.id) || 0) + 1);
    }
    return [...seen].filter(([, n]) => n > 1).map(([id, n]) => `${id} x${n}`);
  });
  if (duplicates.length) fail('ids used more than once: ' + duplicates.join(', '));

  // One plot's markers: for each id, where it is and whether the browser's
  // hit test at its centre lands in its plot's clipped group.
  async function check(plot, ids) {
    const found = await page.evaluate(async (plot, ids) => {
      const svg = document.querySelector(`svg[data-plot='${plot}']`);
      if (!svg) return { missing_plot: true };
      const frame = svg.querySelector(':scope > rect[stroke]').getBoundingClientRect();
      const out = {};
      for (const id of ids) {
        const marker = svg.querySelector(`[data-id='${CSS.escape(id)}']`);
        if (!marker) { out[id] = 'no marker'; continue; }
        marker.scrollIntoView({ block: 'center' });
        await new Promise((r) => requestAnimationFrame(r));
        const box = marker.getBoundingClientRect();
        const f = svg.querySelector(':scope > rect[stroke]').getBoundingClientRect();
        const x = box.x + box.width / 2, y = box.y + box.height / 2;
        if (x < f.left || x > f.right || y < f.top || y > f.bottom) {
          out[id] = `outside the plot frame (${x.toFixed(0)}, ${y.toFixed(0)})`;
          continue;
        }
        const group = marker.closest('g[clip-path]');
        // The clip path the browser applies: an id is the page's, so a
        // shared one resolves to the first plot's clip path.
        const url = group && group.getAttribute('clip-path').match(/#([^)]*)\)/);
        const clip = url && document.getElementById(url[1]);
        if (clip && !svg.contains(clip)) {
          out[id] = `clipped by another plot's clip path (#${url[1]})`;
          continue;
        }
        if (clip) {
          const r = clip.querySelector('rect');
          const m = svg.getScreenCTM();
          const left = m.a * r.x.baseVal.value + m.e;
          const top = m.d * r.y.baseVal.value + m.f;
          const right = left + m.a * r.width.baseVal.value;
          const bottom = top + m.d * r.height.baseVal.value;
          if (x < left || x > right || y < top || y > bottom) {
            out[id] = `outside its clip rectangle (${x.toFixed(0)}, ${y.toFixed(0)})`;
            continue;
          }
        }
        const hit = document.elementFromPoint(x, y);
        if (!hit || !group || !group.contains(hit)) {
          out[id] = `not visible: the hit test at (${x.toFixed(0)}, ` +
            `${y.toFixed(0)}) finds ${hit ? hit.outerHTML.slice(0, 60) : 'nothing'}`;
          continue;
        }
        out[id] = 'ok';
      }
      return { frame: frame.width > 0, markers: out };
    }, plot, ids);
    if (found.missing_plot) { fail(`no plot data-plot='${plot}'`); return; }
    let ok = 0;
    for (const [id, state] of Object.entries(found.markers)) {
      if (state === 'ok') ++ok; else fail(`${plot} plot: crossing ${id}: ${state}`);
    }
    console.log(`${plot} plot: ${ok} of ${ids.length} crossings visible`);
  }
  await check('gcp', controlled);
  await check('trajectory', matched);

  if (shots) {
    mkdirSync(shots, { recursive: true });
    const figures = [
      ['report-gcp-residuals.png', "svg[data-plot='gcp']"],
      ['report-gcp-table.png', 'div.scroll'],
      ['report-camera-residuals.png', 'div#camera-residuals'],
      ['report-before-after.png', 'svg[data-plot^=\'rms-\']'],
    ];
    for (const [file, selector] of figures) {
      const element = await page.$(selector);
      if (!element) { fail(`screenshot: nothing matches ${selector}`); continue; }
      await element.screenshot({ path: `${shots}/${file}` });
      console.log(`screenshot: ${shots}/${file}`);
    }
  }
} finally {
  await browser.close();
}
if (failures) {
  console.error(`${failures} check(s) failed`);
  process.exit(1);
}
console.log('ok: every control and check crossing visible in its plots');
