// ctest server_page: zebrageo serve's web page in Debian's Chromium,
// headless, driven by puppeteer-core. The test submits jobs through the
// API (nothing by hand), then checks that the page lists them as the
// server renders it, follows their progress live without a reload (the
// state turns "done", a report link appears), cancels a queued job with its
// button, opens a report, and takes a screenshot.
// Usage: node check_page.mjs ZEBRAGEO_BINARY WORK_FOLDER SCREENSHOT_PNG
import { spawn, execFileSync } from 'node:child_process';
import { cpSync, mkdirSync, readFileSync } from 'node:fs';
import puppeteer from 'puppeteer-core';

const [zebrageo, work, screenshot] = process.argv.slice(2);
const chromium = '/usr/bin/chromium';
const root = `${work}/root`;
mkdirSync(`${root}/surveys`, { recursive: true });
// A small survey (80 m, 2 crossings, 640x480 images): a few seconds a run.
execFileSync(zebrageo, ['--log-level', 'error', 'simulate', '--preset', 'demo',
  '--seed', '1', '--set', 'road_length_m=80', '--set', 'num_crossings=2',
  '--set', 'num_stale_crossings=0', '--set', 'min_crossing_spacing_m=25',
  '--set', 'image_width=640', '--set', 'image_height=480', '--set',
  'focal_px=560', '--set', 'supersampling=2', '--set', 'exposure_spacing_m=4',
  '-o', `${root}/surveys/a`]);
cpSync(`${root}/surveys/a`, `${root}/surveys/b`, { recursive: true });

const server = spawn(zebrageo, ['serve', '--data-root', root, '--port', '0',
  '--workers', '1'], { stdio: ['ignore', 'pipe', 'inherit'] });
const fail = (message) => {
  console.error('FAIL: ' + message);
  server.kill('SIGKILL');
  process.exit(1);
};
const base = await new Promise((resolve, reject) => {
  let text = '';
  server.stdout.on('data', (chunk) => {
    text += chunk;
    const match = text.match(/listening on (http:\/\/127\.0\.0\.1:\d+)/);
    if (match) resolve(match[1]);
  });
  server.on('exit', () => reject(new Error('the server ended: ' + text)));
});

async function submit(folder, name) {
  const response = await fetch(base + '/jobs', {
    method: 'POST', headers: { 'Content-Type': 'application/json' },
    body: JSON.stringify({ folder, name }) });
  if (response.status !== 201) fail('POST /jobs: ' + response.status);
  return (await response.json()).id;
}
const first = await submit('surveys/a', 'first drive');
const second = await submit('surveys/b', 'second <drive>');
const third = await submit('surveys/a', 'to cancel');

const browser = await puppeteer.launch({
  executablePath: chromium,
  headless: true,
  userDataDir: `${work}/chromium-profile`,
  args: ['--no-sandbox', '--disable-gpu', '--disable-background-networking',
         '--disable-component-update', '--no-first-run', '--disable-sync',
         '--disable-quic'],
});
try {
  const page = await browser.newPage();
  await page.setViewport({ width: 1100, height: 520 });
  const errors = [];
  page.on('pageerror', (error) => errors.push(String(error)));
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  await page.goto(base + '/', { waitUntil: 'load' });

  // The server's own rendering: three rows, the name escaped.
  const rows = await page.$$eval('#jobs tr', (trs) => trs.map((tr) => tr.id));
  for (const id of [first, second, third]) {
    if (!rows.includes('job-' + id)) fail(`job ${id} not listed: ${rows}`);
  }
  const name = await page.$eval(`#job-${second} td:nth-child(2)`, (td) => td.textContent);
  if (name !== 'second <drive>') fail('name shown as ' + name);

  // Cancel the third (queued behind the others) with its button.
  await page.click(`#job-${third} button[data-cancel]`);
  await page.waitForFunction((id) => {
    const state = document.querySelector(`#job-${id} .state`);
    return state && state.textContent === 'cancelled';
  }, { timeout: 30000 }, third);

  // Live progress without a reload: running with a stage, then done.
  const stages = new Set();
  let shot = false;
  const deadline = Date.now() + 240000;
  let states = [];
  while (Date.now() < deadline) {
    states = await page.$$eval('#jobs tr', (trs) => trs.map((tr) => [
      tr.id, tr.querySelector('.state').textContent,
      tr.querySelector('td:nth-child(4)').textContent]));
    for (const [id, state, stage] of states) {
      if (state !== 'running' || !stage) continue;
      stages.add(stage);
      // The picture of docs/server.md: a job in the middle of its run.
      const width = await page.$eval(`#${id} .bar div`, (d) => d.style.width);
      if (!shot && width !== '0%') {
        await page.screenshot({ path: screenshot });
        shot = true;
      }
    }
    const done = states.filter(([id, state]) =>
      state === 'done' && [`job-${first}`, `job-${second}`].includes(id));
    if (done.length === 2) break;
    await new Promise((r) => setTimeout(r, 300));
  }
  if (states.filter(([, s]) => s === 'done').length !== 2) fail('not done: ' + JSON.stringify(states));
  if (stages.size === 0) fail('no running stage was shown');
  const refreshes = await page.$eval('body', (b) => Number(b.dataset.refreshes || 0));
  if (refreshes < 3) fail('the page refreshed ' + refreshes + ' times');
  const width = await page.$eval(`#job-${first} .bar div`, (d) => d.style.width);
  if (width !== '100%') fail('progress bar at ' + width);
  if (errors.length) fail('page errors: ' + errors.join('; '));
  if (!shot) await page.screenshot({ path: screenshot });

  // The report link opens the job's report.html.
  const href = await page.$eval(`#job-${first} a[href$="/report"]`, (a) => a.href);
  const report = await browser.newPage();
  const response = await report.goto(href, { waitUntil: 'load' });
  if (response.status() !== 200) fail('report: ' + response.status());
  const html = await report.content();
  if (!/<h1|<h2/.test(html)) fail('the report has no heading');
  console.log(`page: 3 jobs listed, stages seen live: ${[...stages].join(', ')}; ` +
              `${refreshes} refreshes; screenshot ${screenshot}`);
} finally {
  await browser.close();
  server.kill('SIGTERM');
}
