// Opens the viewer at URL in headless chromium, waits until the map, the image and its keypoints are drawn, checks
// what the page shows and writes a screenshot. Prints the page's status and pixel counts as JSON; exits 1 on a
// failed check. Usage: node browser_check.mjs URL SCREENSHOT.png [--finished | --live]
//   --finished: a `varslam view` page (map and a frame image, no keypoints);
//   --live: the run is still going: waits for its end and wants several frames streamed before it.
import puppeteer from 'puppeteer-core';

const [url, screenshot, ...rest] = process.argv.slice(2);
const finished = rest.includes('--finished');
const live = rest.includes('--live');
const dense = rest.includes('--dense');

const browser = await puppeteer.launch({
  executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
  headless: true,
  args: ['--no-sandbox', '--disable-dev-shm-usage', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'],
});
let failed = false;
try {
  const page = await browser.newPage();
  await page.setViewport({ width: 1600, height: 950 });
  const errors = [];
  page.on('pageerror', (e) => errors.push(e.message));
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  await page.goto(url);
  const ready = finished
    ? () => window.viewerStatus && viewerStatus.maps > 0 && viewerStatus.points > 0 && viewerStatus.frames > 0
    : () => window.viewerStatus && viewerStatus.maps > 0 && viewerStatus.points > 0 && viewerStatus.drawnMarks > 0;
  try {
    await page.waitForFunction(ready, { timeout: 90000, polling: 200 });
  } catch (e) {
    const seen = await page.evaluate(() => window.viewerStatus);
    console.error(`FAILED: the page never showed the run (${e.message}); status ${JSON.stringify(seen)}; ` +
                  `page errors: ${errors.join(' | ')}`);
    throw e;
  }
  let framesBeforeEnd = 0;
  if (live) {
    await page.waitForFunction(() => viewerStatus.done, { timeout: 600000, polling: 100 });
    framesBeforeEnd = await page.evaluate(() => viewerStatus.framesBeforeDone);
  }
  if (dense) await page.waitForFunction(() => viewerStatus.densePoints > 0, { timeout: 30000, polling: 100 });
  await new Promise((r) => setTimeout(r, 700));  // the last render and image decode
  // Pixels of the 3-D view off the background colour.
  const scenePixels = () => page.evaluate(() => {
    const scene = document.querySelector('#scene canvas');
    const copy = document.createElement('canvas');
    copy.width = scene.width;
    copy.height = scene.height;
    const g = copy.getContext('2d');
    g.drawImage(scene, 0, 0);
    const s = g.getImageData(0, 0, copy.width, copy.height).data;
    let n = 0;
    for (let i = 0; i < s.length; i += 4) if (Math.abs(s[i] - 0x15) + Math.abs(s[i + 1] - 0x18) + Math.abs(s[i + 2] - 0x1c) >= 60) ++n;
    return n;
  });
  let denseToggle = null;
  if (dense) {
    const render = () => new Promise((r) => setTimeout(r, 400));
    const withLayer = await scenePixels();
    await page.click('#show-dense');
    await render();
    const without = await scenePixels();
    const hidden = await page.evaluate(() => !viewerStatus.denseVisible);
    await page.click('#show-dense');
    await render();
    denseToggle = { withLayer, without, hidden, shownAgain: await page.evaluate(() => viewerStatus.denseVisible) };
  }
  const result = await page.evaluate(() => {
    const near = (d, i, rgb) => Math.abs(d[i] - rgb[0]) + Math.abs(d[i + 1] - rgb[1]) + Math.abs(d[i + 2] - rgb[2]) < 60;
    const scene = document.querySelector('#scene canvas');
    const copy = document.createElement('canvas');
    copy.width = scene.width;
    copy.height = scene.height;
    const g = copy.getContext('2d');
    g.drawImage(scene, 0, 0);
    const s = g.getImageData(0, 0, copy.width, copy.height).data;
    let scenePixels = 0;
    for (let i = 0; i < s.length; i += 4) if (!near(s, i, [0x15, 0x18, 0x1c])) ++scenePixels;
    const img = document.getElementById('image');
    const d = img.getContext('2d').getImageData(0, 0, img.width, img.height).data;
    let inlierPixels = 0, personPixels = 0;
    for (let i = 0; i < d.length; i += 4) {
      if (near(d, i, [0x3d, 0xdc, 0x84])) ++inlierPixels;
      if (near(d, i, [0xff, 0x4f, 0xd8])) ++personPixels;
    }
    return { ...window.viewerStatus, scenePixels, inlierPixels, personPixels,
             stateLine: document.getElementById('state-line').textContent,
             events: document.getElementById('events').children.length };
  });
  result.pageErrors = errors;
  result.denseToggle = denseToggle;
  result.framesBeforeEnd = framesBeforeEnd;
  await page.screenshot({ path: screenshot });
  console.log(JSON.stringify(result));
  const checks = [
    ['3-D map drawn (pixels off the background)', result.scenePixels > 2000],
    ['map points received', result.points > 50],
    ['no page errors', errors.length === 0],
  ];
  if (live) checks.push(['frames streamed while the run went on', framesBeforeEnd >= 5]);
  if (dense) {
    checks.push(['dense layer received', result.densePoints > 1000 && result.denseRegions > 5]);
    checks.push(['dense layer drawn: hiding it clears pixels', denseToggle.hidden && denseToggle.withLayer > denseToggle.without + 5000]);
    checks.push(['dense layer shown again', denseToggle.shownAgain]);
  }
  if (!finished) {
    checks.push(['keypoints drawn over the image', result.drawnMarks > 50 && result.inlierPixels > 200]);
    checks.push(['state line shows tracking', /tracking|lost|initializing/.test(result.stateLine)]);
  } else {
    checks.push(['frame image shown', result.frames > 0]);
  }
  for (const [what, ok] of checks) {
    if (!ok) {
      console.error(`FAILED: ${what}`);
      failed = true;
    }
  }
} finally {
  await browser.close();
}
process.exit(failed ? 1 : 0);
