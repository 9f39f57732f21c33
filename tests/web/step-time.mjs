// Lesson 6's step time (the bunny, on the fast engine, the readouts' "step time") in several
// builds of the page, for docs/web.md: each URL opened in turn, ROUNDS times, 30 frames played
// each time; prints the median of each opening and of each URL. Serve each build (scripts/web.sh
// DIR) on a port of its own first, e.g. `python3 -m http.server -d DIR PORT`.
//
//   node tests/web/step-time.mjs ROUNDS URL [URL ...]
//
// TETLAB_FRAGMENT replaces `lesson=6` (the link opened, e.g. `scene=cube&resolution=15&engine=gpu`
// for the 20k-tet block on the GPU engine), FRAMES the 30 frames, and TETLAB_WEBGPU=1 opens
// Chromium with WebGPU on SwiftShader (the flags of tests/web/drive.mjs).

import puppeteer from "puppeteer-core";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";

const [roundsText, ...urls] = process.argv.slice(2);
const rounds = Number(roundsText);
if (!Number.isInteger(rounds) || rounds < 1 || urls.length === 0) {
  console.error("usage: node tests/web/step-time.mjs ROUNDS URL [URL ...]");
  process.exit(2);
}
const browser = await puppeteer.launch({
  executablePath: process.env.CHROMIUM ?? "/usr/bin/chromium",
  headless: true,
  userDataDir: fs.mkdtempSync(path.join(os.tmpdir(), "tetlab-step-time-")),
  defaultViewport: { width: 1280, height: 800 },
  args: ["--no-sandbox", "--no-first-run", "--disable-background-networking",
    "--enable-unsafe-swiftshader", "--window-size=1280,800",
    ...(process.env.TETLAB_WEBGPU === "1"
      ? ["--enable-unsafe-webgpu", "--use-angle=vulkan", "--enable-features=Vulkan",
        "--use-vulkan=swiftshader", "--use-webgpu-adapter=swiftshader"]
      : ["--disable-gpu"])],
});
const page = await browser.newPage();
const state = () => page.evaluate(() => window.tetlab_state && window.tetlab_state()).catch(() => null);
const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));
const median = (values) => [...values].sort((a, b) => a - b)[Math.floor(values.length / 2)];

const fragment = process.env.TETLAB_FRAGMENT ?? "lesson=6";
const wanted = Number(process.env.FRAMES ?? 30);
const results = new Map(urls.map((url) => [url, []]));
for (let round = 0; round < rounds; round++) {
  for (const url of urls) {
    await page.goto("about:blank");
    await page.goto(`${url}#${fragment}`);
    let opened = null;
    for (const deadline = Date.now() + 60000; Date.now() < deadline && !opened; await sleep(100)) {
      const s = await state();
      const lesson6 = fragment.includes("lesson=6");
      opened = s && s.tets > 0 && (!lesson6 || (s.lesson && s.tets === 1351)) ? s : null;
    }
    if (!opened) {
      console.error(`${url}: #${fragment} did not open within a minute (lesson 6: is ../shared/meshes beside the page?)`);
      process.exit(1);
    }
    console.log(`${url}#${fragment}: ${opened.tets} tets, ${opened.engine}`);
    await page.keyboard.press("Space");
    const times = [];
    let last = -1;
    for (const deadline = Date.now() + 600000; times.length < wanted && Date.now() < deadline; await sleep(20)) {
      const s = await state();
      if (s && s.playing && s.frame !== last && s.step_ms > 0) {
        times.push(s.step_ms);
        last = s.frame;
      }
    }
    if (times.length < wanted) {
      console.error(`${url}: #${fragment} played ${times.length} frames in ten minutes, not ${wanted}`);
      process.exit(1);
    }
    results.get(url).push(median(times));
    console.log(`${url}: ${median(times).toFixed(2)} ms a step (median of ${wanted} frames)`);
  }
}
for (const [url, medians] of results) {
  console.log(`${url}: median ${median(medians).toFixed(2)} ms over ${medians.length} openings: ${medians.map((m) => m.toFixed(2)).join(", ")}`);
}
await browser.close();
