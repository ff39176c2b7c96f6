// SPDX-License-Identifier: MIT
// Opens a run's view.html from file:// in headless Chromium (Playwright) and checks that the
// page plays the run: the animation lasts the simulated time of the run's own summary
// (run.json), one animated node per part with the writer's names (part_<i>_<family>), the time
// slider moves the animation, and a screenshot is not blank.
//   node view_test.mjs FOLDER [CHROMIUM]
import fs from "node:fs";
import path from "node:path";
import { pathToFileURL } from "node:url";
import { chromium } from "playwright-core";

const [folder, executablePath = "/usr/bin/chromium"] = process.argv.slice(2);
if (!folder) {
  console.error("usage: node view_test.mjs FOLDER [CHROMIUM]");
  process.exit(2);
}
// Times travel through glTF as 32-bit floats: within FLT_EPSILON (2^-23) times max(1, |t|).
const kFloatEpsilon = 2 ** -23;
// A blank page is one colour; a page showing the plate and parts has many (shading). We ask for
// more than one colour and a most common colour (the background) under 99 % of the pixels.
const kMaxDominantShare = 0.99;

const failures = [];
function check(ok, message) {
  console.log(`${ok ? "ok  " : "FAIL"} ${message}`);
  if (!ok) failures.push(message);
}

const summary = JSON.parse(fs.readFileSync(path.join(folder, "run.json"), "utf8"));
const simulated = summary.simulated_seconds;
const parts = summary.parts;

const browser = await chromium.launch({
  executablePath,
  // WebGL without a GPU: SwiftShader through ANGLE (Chromium asks for the opt-in since 2025).
  args: ["--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist"],
});
try {
  const page = await browser.newPage({ viewport: { width: 1000, height: 900 } });
  const pageErrors = [];
  page.on("pageerror", (e) => pageErrors.push(String(e)));
  page.on("console", (m) => {
    if (m.type() === "error") pageErrors.push(m.text());
  });
  await page.goto(pathToFileURL(path.resolve(folder, "view.html")).href);
  await page.waitForFunction(
    () => window.rheofeedView && (window.rheofeedView.ready || window.rheofeedView.error),
    null, { timeout: 60000 });
  const view = await page.evaluate(() => ({
    error: window.rheofeedView.error,
    duration: window.rheofeedView.duration,
    nodeNames: window.rheofeedView.nodeNames,
    animated: window.rheofeedView.animatedNodeNames,
  }));
  check(view.error === null, `page reports no error (${view.error})`);
  check(pageErrors.length === 0, `no script errors (${pageErrors.join("; ")})`);

  check(Math.abs(view.duration - simulated) <= kFloatEpsilon * Math.max(1, simulated),
        `animation duration ${view.duration} s = simulated time ${simulated} s`);

  const partNames = view.nodeNames.filter((n) => /^part_\d+_/.test(n));
  check(partNames.length === parts, `${partNames.length} part nodes = ${parts} parts of the run`);
  const indices = partNames.map((n) => parseInt(n.split("_")[1], 10)).sort((a, b) => a - b);
  check(indices.every((v, i) => v === i), `part nodes numbered 0..${parts - 1} (${indices})`);
  const animatedParts = view.animated.filter((n) => /^part_\d+_/.test(n)).sort();
  check(JSON.stringify(animatedParts) === JSON.stringify([...partNames].sort()),
        `every part node and only they are animated as parts (${animatedParts.length})`);
  check(view.nodeNames.includes("plate") && view.animated.includes("plate"),
        "the vibrating plate is a node and is animated (full vibration)");

  // The slider's time: half way through, paused.
  const half = await page.evaluate((t) => {
    window.rheofeedView.pause();
    window.rheofeedView.setTime(t);
    return { time: window.rheofeedView.time, readout: document.getElementById("time").textContent };
  }, simulated / 2);
  check(Math.abs(half.time - simulated / 2) < 1e-12, `setTime puts the animation at ${half.time} s`);
  check(half.readout.startsWith(`t = ${(simulated / 2).toFixed(3)} s`), `readout "${half.readout}"`);

  const plots = await page.evaluate(() =>
    Array.from(document.querySelectorAll("#plots img")).map((i) => ({ src: i.getAttribute("src"),
                                                                    width: i.naturalWidth })));
  for (const p of plots) check(p.width > 0, `plot ${p.src} shows (${p.width} px wide)`);

  // A screenshot of the 3D view, decoded in the page (a 2D canvas reads PNG pixels).
  await page.waitForTimeout(200);  // a few frames at the new time
  const shot = await page.locator("#view canvas").screenshot();
  fs.writeFileSync(path.join(folder, "view_screenshot.png"), shot);
  const pixels = await page.evaluate(async (b64) => {
    const img = new Image();
    img.src = "data:image/png;base64," + b64;
    await img.decode();
    const c = document.createElement("canvas");
    c.width = img.width;
    c.height = img.height;
    const g = c.getContext("2d");
    g.drawImage(img, 0, 0);
    const d = g.getImageData(0, 0, c.width, c.height).data;
    const counts = new Map();
    for (let i = 0; i < d.length; i += 4) {
      const key = (d[i] << 16) | (d[i + 1] << 8) | d[i + 2];
      counts.set(key, (counts.get(key) || 0) + 1);
    }
    return { total: d.length / 4, colours: counts.size, dominant: Math.max(...counts.values()) };
  }, shot.toString("base64"));
  const share = pixels.dominant / pixels.total;
  check(pixels.total > 0 && pixels.colours > 1 && share < kMaxDominantShare,
        `screenshot not blank: ${pixels.colours} colours, most common ${(100 * share).toFixed(1)} %` +
        ` of ${pixels.total} pixels`);
} finally {
  await browser.close();
}
if (failures.length) {
  console.error(`view_test: ${failures.length} check(s) failed`);
  process.exit(1);
}
console.log("view_test: all checks passed");
