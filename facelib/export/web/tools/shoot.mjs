// Drive the web player in Debian's headless chromium (puppeteer-core) and take screenshots.
// Usage: node tools/shoot.mjs PAGE_DIR OUT_DIR JOB.json
// JOB: {"bg": "00ff00", "camera": [pose16, yfov, near, far] | null, "times": [s...],
//       "play_ms": 600, "chromium": "/usr/bin/chromium"}
// Writes OUT_DIR/seek_<i>.png per time, OUT_DIR/play_0.png and play_1.png taken while the
// page plays, and prints a JSON summary (times the page reported, errors).
import { readFile } from "node:fs/promises";
import path from "node:path";
import puppeteer from "puppeteer-core";

const [pageDir, outDir, jobPath] = process.argv.slice(2);
const job = JSON.parse(await readFile(jobPath, "utf8"));
const browser = await puppeteer.launch({
  executablePath: job.chromium || "/usr/bin/chromium",
  headless: true,
  args: ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
         "--autoplay-policy=no-user-gesture-required", "--allow-file-access-from-files"],
});
const summary = { errors: [], seek: [], play: [] };
try {
  const page = await browser.newPage();
  page.on("pageerror", (e) => summary.errors.push(String(e)));
  await page.setViewport({ width: 680, height: 560 });
  const url = "file://" + path.resolve(pageDir, "index.html") + (job.bg ? `?bg=${job.bg}` : "");
  await page.goto(url, { waitUntil: "load" });
  await page.waitForFunction(() => document.body.dataset.ready || document.body.dataset.error,
                             { timeout: 60000 });
  const error = await page.evaluate(() => document.body.dataset.error);
  if (error) throw new Error(error);
  if (job.camera) await page.evaluate((c) => window.facelibPlayer.setCamera(...c), job.camera);
  const canvas = await page.$("#view");
  const frame = () => page.evaluate(() => new Promise((r) => requestAnimationFrame(() =>
    requestAnimationFrame(r))));
  for (const [i, t] of (job.times || []).entries()) {
    await page.evaluate((s) => window.facelibPlayer.seek(s), t);
    await frame();
    await canvas.screenshot({ path: path.join(outDir, `seek_${i}.png`) });
    summary.seek.push(await page.evaluate(() => window.facelibPlayer.time()));
  }
  if (job.play_ms) {
    await page.evaluate(() => { window.facelibPlayer.seek(0); return window.facelibPlayer.play(); });
    for (const i of [0, 1]) {
      await new Promise((r) => setTimeout(r, job.play_ms));
      await canvas.screenshot({ path: path.join(outDir, `play_${i}.png`) });
      summary.play.push(await page.evaluate(() => window.facelibPlayer.time()));
    }
  }
  if (job.full) await page.screenshot({ path: path.join(outDir, "page.png") });
} finally {
  await browser.close();
}
console.log(JSON.stringify(summary));
