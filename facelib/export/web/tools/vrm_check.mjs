// Load a facelib VRM avatar (and optionally a VRM animation) with @pixiv/three-vrm in
// Debian's headless chromium (puppeteer-core), play the animation, and print what the
// avatar shows as JSON (see vrm_page.js).
// Usage: node tools/vrm_check.mjs JOB.json
// JOB: {"vrm": PATH, "vrma": PATH | null, "times": [s...], "chromium": PATH,
//       "shoot": {"t": s, "png": PATH} | null}
import { readFile } from "node:fs/promises";
import path from "node:path";
import { fileURLToPath } from "node:url";
import * as esbuild from "esbuild";
import puppeteer from "puppeteer-core";

const here = path.dirname(fileURLToPath(import.meta.url));
const job = JSON.parse(await readFile(process.argv[2], "utf8"));
const bundle = await esbuild.build({
  entryPoints: [path.join(here, "vrm_page.js")], bundle: true, write: false, format: "iife",
  target: "es2020", logLevel: "error",
});
const files = {
  vrm: (await readFile(job.vrm)).toString("base64"),
  vrma: job.vrma ? (await readFile(job.vrma)).toString("base64") : null,
  times: job.shoot ? [job.shoot.t] : job.times || [],
  shoot: job.shoot ? job.shoot.t : null,
};
const browser = await puppeteer.launch({
  executablePath: job.chromium || "/usr/bin/chromium", headless: true,
  args: ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader"],
});
let result;
try {
  const page = await browser.newPage();
  const errors = [];
  page.on("pageerror", (e) => errors.push(String(e)));
  page.on("console", (m) => { if (m.type() === "warning" || m.type() === "error") errors.push(m.text()); });
  await page.setViewport({ width: 480, height: 480 });
  await page.goto("about:blank");
  await page.evaluate((f) => { window.FACELIB_VRM = f; }, files);
  await page.addScriptTag({ content: bundle.outputFiles[0].text });
  await page.waitForFunction(() => window.FACELIB_RESULT, { timeout: 120000 });
  result = await page.evaluate(() => window.FACELIB_RESULT);
  result.console = errors;
  if (job.shoot && !result.error) {
    await (await page.$("#view")).screenshot({ path: job.shoot.png });
  }
} finally {
  await browser.close();
}
console.log(JSON.stringify(result));
