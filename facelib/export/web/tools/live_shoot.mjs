// Drive the live page (examples/live) in Debian's headless chromium against a running
// `facelib serve`: type a line, then capture the canvas twice while the audio plays.
// Usage: node tools/live_shoot.mjs PAGE.html OUT_DIR JOB.json
// JOB: {"server": "ws://127.0.0.1:PORT", "line": "...", "bg": "00ff00", "open": 0.3,
//       "drop": 0.2, "size": "320x240", "timeout_ms": 60000, "chromium": "/usr/bin/chromium"}
// Capture 0 is the first drawn frame with sound playing and jawOpen >= open; capture 1 a
// later one with sound playing and jawOpen at least `drop` away from the first. Each capture is the canvas
// right after that frame was drawn (live_<i>.png) with the state the page reported for it.
// Writes page.png (the whole page) and prints a JSON summary.
import { readFile, writeFile } from "node:fs/promises";
import path from "node:path";
import puppeteer from "puppeteer-core";

const [pagePath, outDir, jobPath] = process.argv.slice(2);
const job = JSON.parse(await readFile(jobPath, "utf8"));
const timeout = job.timeout_ms || 60000;
const browser = await puppeteer.launch({
  executablePath: job.chromium || "/usr/bin/chromium",
  headless: true,
  args: ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
         "--autoplay-policy=no-user-gesture-required", "--allow-file-access-from-files"],
});
const summary = { errors: [], captures: [], final: null };

async function capture(page, test, args, name) {
  const got = await page.evaluate((source, a) => {
    const holds = new Function("s", "a", source);
    return Promise.race([window.facelibPlayer.live.capture((s) => holds(s, a)),
                         new Promise((r) => setTimeout(() => r(null), a.timeout))]);
  },
    test, { ...args, timeout });
  if (!got) {
    const state = await page.evaluate(() => window.facelibPlayer.live.state());
    throw new Error(`no frame for ${name} within ${timeout} ms; state ${JSON.stringify(state)}`);
  }
  const png = Buffer.from(got.png.split(",")[1], "base64");
  await writeFile(path.join(outDir, `${name}.png`), png);
  summary.captures.push(got.state);
  console.error(name, JSON.stringify(got.state));
  return got.state;
}

try {
  const page = await browser.newPage();
  page.on("pageerror", (e) => summary.errors.push(String(e)));
  await page.setViewport({ width: 680, height: 600 });
  const query = new URLSearchParams({ server: job.server, ...(job.bg ? { bg: job.bg } : {}),
                                     ...(job.size ? { size: job.size } : {}) });
  await page.goto("file://" + path.resolve(pagePath) + "?" + query, { waitUntil: "load" });
  await page.waitForFunction(() => document.body.dataset.ready || document.body.dataset.error,
                             { timeout });
  const error = await page.evaluate(() => document.body.dataset.error);
  if (error) throw new Error(error);
  await page.waitForFunction(() => window.facelibPlayer.live.state().started, { timeout });
  await page.type("#line", job.line);
  await page.keyboard.press("Enter");
  const first = await capture(page, "return s.audible && s.shown && s.shown.jawOpen >= a.open;",
                              { open: job.open ?? 0.3 }, "live_0");
  await capture(page, "return s.audible && s.shown && s.shown.i > a.i && " +
                "Math.abs(s.shown.jawOpen - a.jaw) >= a.drop;",
                { i: first.shown.i, jaw: first.shown.jawOpen, drop: job.drop ?? 0.2 }, "live_1");
  await page.screenshot({ path: path.join(outDir, "page.png") });
  summary.final = await page.evaluate(() => window.facelibPlayer.live.state());
} finally {
  await browser.close();
}
console.log(JSON.stringify(summary));
