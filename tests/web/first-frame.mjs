// How long the page takes to draw its first frame over a slow link. Each folder built by
// scripts/web.sh is served here as a static host serves it (gzip-compressed, as browsers ask) and
// opened ROUNDS times in a fresh headless Chromium with the network emulated (DevTools'
// Network.emulateNetworkConditions: 10 Mbit/s down, 5 Mbit/s up, 20 ms latency unless MBITS and
// LATENCY_MS say otherwise); prints, for each opening, the bytes the page transferred and the
// time from the request to the console's "tetlab ready" line, and the median of each folder.
//
//   node tests/web/first-frame.mjs ROUNDS SITE_FOLDER [SITE_FOLDER ...]

import puppeteer from "puppeteer-core";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";
import http from "node:http";
import zlib from "node:zlib";

const [roundsText, ...folders] = process.argv.slice(2);
const rounds = Number(roundsText);
if (!Number.isInteger(rounds) || rounds < 1 || folders.length === 0) {
  console.error("usage: node tests/web/first-frame.mjs ROUNDS SITE_FOLDER [SITE_FOLDER ...]");
  process.exit(2);
}
const TYPES = { ".html": "text/html", ".js": "text/javascript", ".wasm": "application/wasm" };

/// Serves `folder` on a free port of localhost, each file gzipped (level 9, once); returns the
/// server and its address.
async function serve(folder) {
  const gzipped = new Map();
  const server = http.createServer((request, response) => {
    const name = decodeURIComponent(new URL(request.url, "http://x").pathname);
    const file = path.join(folder, name.endsWith("/") ? `${name}index.html` : name);
    if (!file.startsWith(path.resolve(folder)) || !fs.existsSync(file) || fs.statSync(file).isDirectory()) {
      response.writeHead(404).end();
      return;
    }
    if (!gzipped.has(file)) gzipped.set(file, zlib.gzipSync(fs.readFileSync(file), { level: 9 }));
    response.writeHead(200, {
      "Content-Type": TYPES[path.extname(file)] ?? "application/octet-stream",
      "Content-Encoding": "gzip",
    });
    response.end(gzipped.get(file));
  });
  await new Promise((resolve) => server.listen(0, "127.0.0.1", resolve));
  return { server, url: `http://127.0.0.1:${server.address().port}/` };
}
const served = [];
for (const folder of folders) served.push({ folder, ...(await serve(path.resolve(folder))) });
const urls = served.map((s) => s.url);
const mbits = Number(process.env.MBITS ?? 10);
const latency = Number(process.env.LATENCY_MS ?? 20);
const median = (values) => [...values].sort((a, b) => a - b)[Math.floor(values.length / 2)];
const results = new Map(urls.map((url) => [url, []]));

for (let round = 0; round < rounds; round++) {
  for (const url of urls) {
    // A fresh browser each time: nothing cached, the compiled WebAssembly included.
    const browser = await puppeteer.launch({
      executablePath: process.env.CHROMIUM ?? "/usr/bin/chromium",
      headless: true,
      userDataDir: fs.mkdtempSync(path.join(os.tmpdir(), "tetlab-first-frame-")),
      defaultViewport: { width: 1280, height: 800 },
      args: ["--no-sandbox", "--disable-gpu", "--no-first-run", "--disable-background-networking",
        "--disable-component-update", "--disable-sync", "--disable-quic",
        "--enable-unsafe-swiftshader", "--window-size=1280,800"],
    });
    const page = await browser.newPage();
    const cdp = await page.createCDPSession();
    await cdp.send("Network.enable");
    await cdp.send("Network.setCacheDisabled", { cacheDisabled: true });
    await cdp.send("Network.emulateNetworkConditions", {
      offline: false,
      latency,
      downloadThroughput: (mbits * 1e6) / 8,
      uploadThroughput: (mbits * 1e6) / 16,
    });
    let bytes = 0;
    cdp.on("Network.loadingFinished", (event) => { bytes += event.encodedDataLength; });
    let ready;
    const readyLine = new Promise((resolve) => { ready = resolve; });
    page.on("console", (message) => {
      if (message.text().startsWith("tetlab ready")) ready(performance.now());
    });
    const started = performance.now();
    await page.goto(url, { waitUntil: "domcontentloaded" });
    const drawn = await Promise.race([readyLine, new Promise((r) => setTimeout(() => r(null), 120000))]);
    await browser.close();
    if (drawn === null) {
      console.error(`${url}: no "tetlab ready" within two minutes`);
      process.exit(1);
    }
    const seconds = (drawn - started) / 1000;
    results.get(url).push(seconds);
    console.log(`${url}: first frame after ${seconds.toFixed(2)} s, ${(bytes / 1e6).toFixed(2)} MB transferred`);
  }
}
for (const { folder, url, server } of served) {
  const times = results.get(url);
  console.log(`${folder}: median ${median(times).toFixed(2)} s over ${times.length} openings, at ` +
    `${mbits} Mbit/s and ${latency} ms`);
  server.close();
}
