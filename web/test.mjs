// Headless-browser test of bv's web bundle (web/dist, built by web/build.sh):
//
//   node web/test.mjs [--webgl-only] [--shots DIR]
//
// Serves the bundle on a free localhost port, drives Debian's chromium
// (CHROMIUM, default /usr/bin/chromium) through playwright-core, and checks:
// the page loads with no console error, the first frame is not blank, a
// slider dragged on the canvas changes the picture, Copy link then opening
// that link reproduces the scene (screenshots compared), every view drawn
// maximised (through links made from the copied one) is not blank, the
// session persists in local storage, hostile fragments fall back to the
// default scene with a message, long computations (albedo, sampling) run in
// many short steps while frames keep coming, Save scene downloads the scene
// file, Export figure (Ctrl+Shift+S, Enter) downloads a PNG of the window,
// and a dropped MERL table, .brdf model and environment map open. Then the
// first-frame checks again with WebGPU off (WebGL2 only). Screenshots go to
// web/shots (or --shots DIR); timings and the renderer are printed.
//
// WebGPU: a minimal page (plain JavaScript, no bv) first probes whether this
// browser keeps a WebGPU device that presents to a canvas. Where it does, the
// WebGPU page must stay on WebGPU to the end (its renderer is printed last),
// every view is drawn on WebGPU (the environment view included), and a loss
// is tested apart, by destroying the page's device (`GPUDevice.destroy()`):
// the page falls back to WebGL2. Where the minimal page loses its device too,
// the browser is at fault and the WebGPU page is only required to fall back.
// Every loss's reason is printed.
import { chromium } from "playwright-core";
import http from "node:http";
import fs from "node:fs";
import path from "node:path";
import zlib from "node:zlib";
import { fileURLToPath } from "node:url";
import { execFileSync } from "node:child_process";
import os from "node:os";

const here = path.dirname(fileURLToPath(import.meta.url));
const dist = path.join(here, "dist");
const args = process.argv.slice(2);
const shotsArg = args.indexOf("--shots");
const shots = shotsArg >= 0 ? args[shotsArg + 1] : path.join(here, "shots");
const webglOnly = args.includes("--webgl-only");
const W = 1280;
const H = 800;
// The software renderers in CI are slow: generous waits, checked often.
const FIRST_FRAME_TIMEOUT = 60_000;
const SETTLE_MS = Number(process.env.BV_WEB_SETTLE_MS || 3000);
// Chromium's switches for WebGPU in a headless browser without a GPU. With
// `--enable-unsafe-webgpu` alone, headless Chromium 156's GPU process has no
// shared image to back a WebGPU canvas with (it logs "Could not find
// SharedImageBackingFactory … WebgpuSwapChainTexture") and takes the device
// back at the first present: "Device was destroyed", or "A valid external
// Instance reference no longer exists" when the page had asked for a second
// adapter (as wgpu's WebGPU detection does). A page of a few lines does the
// same; the probe below tells which case a browser is. With Vulkan in the
// GPU process (SwiftShader's) the canvas has its backing; ANGLE is then
// named too: left to choose, the GPU process lost WebGL and WebGPU alike at
// the first present, and ANGLE on Vulkan gave no WebGL2 at all.
// BV_WEBGPU_ARGS replaces them (space-separated), e.g. for a real GPU.
const WEBGPU_ARGS = process.env.BV_WEBGPU_ARGS !== undefined
  ? process.env.BV_WEBGPU_ARGS.split(/\s+/).filter(Boolean)
  : ["--enable-unsafe-webgpu", "--enable-features=Vulkan", "--use-vulkan=swiftshader", "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader"];
// How long the probe's minimal page presents frames (the bv page lost its
// device a few seconds after its start on such a browser).
const PROBE_MS = 8000;

fs.mkdirSync(shots, { recursive: true });
let failures = 0;
// Seconds since the start on every check: where a slow CI run spent its
// minutes can be read off its log.
const started = Date.now();
function check(ok, what) {
  const t = ((Date.now() - started) / 1000).toFixed(0).padStart(4);
  console.log(`${ok ? "ok  " : "FAIL"} [${t} s] ${what}`);
  if (!ok) failures++;
}

// ---- a static server for the bundle ----
const types = {
  ".html": "text/html; charset=utf-8",
  ".js": "text/javascript; charset=utf-8",
  ".wasm": "application/wasm",
};
// The probe's minimal WebGPU page: an adapter, a device and a canvas of the
// viewer's size cleared to a changing colour every frame for PROBE_MS; what
// became of the device is left in `window.__probe`.
const PROBE_PAGE = "__webgpu_probe.html";
const PROBE_HTML = `<!DOCTYPE html>
<html><body style="margin:0"><canvas id="c" width="${W}" height="${H}"></canvas>
<script>
window.__probe = (async () => {
  if (!navigator.gpu) return { adapter: null, why: "no navigator.gpu" };
  const adapter = await navigator.gpu.requestAdapter();
  if (!adapter) return { adapter: null, why: "requestAdapter() gave none" };
  const i = adapter.info || {};
  const name = [i.vendor, i.architecture, i.description].filter(Boolean).join(" ");
  const device = await adapter.requestDevice();
  let lost = null;
  device.lost.then((l) => { lost = l.reason + ": " + l.message; });
  const canvas = document.getElementById("c");
  const ctx = canvas.getContext("webgpu");
  ctx.configure({ device, format: navigator.gpu.getPreferredCanvasFormat(), alphaMode: "opaque" });
  const t0 = performance.now();
  let frames = 0;
  await new Promise((done) => {
    const frame = () => {
      const t = (performance.now() - t0) / 1000;
      const enc = device.createCommandEncoder();
      enc.beginRenderPass({ colorAttachments: [{ view: ctx.getCurrentTexture().createView(),
        loadOp: "clear", storeOp: "store", clearValue: { r: 0.5 + 0.5 * Math.sin(3 * t), g: 0.3, b: 0.6, a: 1 } }] }).end();
      device.queue.submit([enc.finish()]);
      frames++;
      if (performance.now() - t0 < ${PROBE_MS} && !lost) requestAnimationFrame(frame);
      else done();
    };
    requestAnimationFrame(frame);
  });
  // A loss is reported asynchronously: give a late one a moment.
  await device.queue.onSubmittedWorkDone().catch(() => {});
  await new Promise((r) => setTimeout(r, 200));
  return { adapter: name || "(unnamed)", frames, ms: Math.round(performance.now() - t0), lost };
})().catch((e) => ({ adapter: null, why: String(e) }));
</script></body></html>
`;

function serve() {
  const server = http.createServer((req, res) => {
    const url = new URL(req.url, "http://localhost");
    if (url.pathname === `/${PROBE_PAGE}`) {
      res.writeHead(200, { "content-type": types[".html"] }).end(PROBE_HTML);
      return;
    }
    const name = url.pathname === "/" ? "index.html" : url.pathname.slice(1);
    const file = path.join(dist, path.normalize(name));
    if (!file.startsWith(dist) || !fs.existsSync(file) || !fs.statSync(file).isFile()) {
      res.writeHead(404).end();
      return;
    }
    res.writeHead(200, { "content-type": types[path.extname(file)] || "application/octet-stream" });
    fs.createReadStream(file).pipe(res);
  });
  return new Promise((resolve) => server.listen(0, "127.0.0.1", () => resolve(server)));
}

// ---- PNG decoding (8-bit RGB/RGBA, not interlaced: what Chromium writes) ----
function decodePng(buf) {
  let pos = 8;
  let width = 0, height = 0, channels = 0;
  const idat = [];
  while (pos < buf.length) {
    const len = buf.readUInt32BE(pos);
    const type = buf.toString("ascii", pos + 4, pos + 8);
    const data = buf.subarray(pos + 8, pos + 8 + len);
    if (type === "IHDR") {
      width = data.readUInt32BE(0);
      height = data.readUInt32BE(4);
      if (data[8] !== 8 || data[12] !== 0) throw new Error("unsupported PNG");
      channels = { 2: 3, 6: 4 }[data[9]];
      if (!channels) throw new Error(`unsupported PNG colour type ${data[9]}`);
    } else if (type === "IDAT") idat.push(data);
    pos += 12 + len;
  }
  const raw = zlib.inflateSync(Buffer.concat(idat));
  const stride = width * channels;
  const px = Buffer.alloc(width * height * 4);
  let prev = Buffer.alloc(stride);
  for (let y = 0; y < height; y++) {
    const f = raw[y * (stride + 1)];
    const line = Buffer.from(raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1)));
    for (let i = 0; i < stride; i++) {
      const a = i >= channels ? line[i - channels] : 0;
      const b = prev[i];
      const c = i >= channels ? prev[i - channels] : 0;
      let p = 0;
      if (f === 1) p = a;
      else if (f === 2) p = b;
      else if (f === 3) p = (a + b) >> 1;
      else if (f === 4) {
        const q = a + b - c;
        const pa = Math.abs(q - a), pb = Math.abs(q - b), pc = Math.abs(q - c);
        p = pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
      }
      line[i] = (line[i] + p) & 255;
    }
    for (let x = 0; x < width; x++) {
      for (let k = 0; k < 3; k++) px[(y * width + x) * 4 + k] = line[x * channels + k];
      px[(y * width + x) * 4 + 3] = 255;
    }
    prev = line;
  }
  return { width, height, px };
}

// Luminance spread and the number of distinct colours of a region (x0, y0,
// x1, y1; default the whole image).
function stats(img, [x0, y0, x1, y1] = [0, 0, img.width, img.height]) {
  const colours = new Set();
  let n = 0, sum = 0, sq = 0;
  for (let y = y0; y < y1; y++) {
    for (let x = x0; x < x1; x++) {
      const i = (y * img.width + x) * 4;
      const [r, g, b] = [img.px[i], img.px[i + 1], img.px[i + 2]];
      colours.add((r << 16) | (g << 8) | b);
      const l = 0.2126 * r + 0.7152 * g + 0.0722 * b;
      n++; sum += l; sq += l * l;
    }
  }
  const mean = sum / n;
  return { colours: colours.size, std: Math.sqrt(Math.max(0, sq / n - mean * mean)), mean };
}

// The share of pixels of a region brighter than its darkest tenth by more
// than `by` levels of luminance (a lit object against a dark background).
function brightShare(img, [x0, y0, x1, y1], by = 40) {
  const ls = [];
  for (let y = y0; y < y1; y++) {
    for (let x = x0; x < x1; x++) {
      const i = (y * img.width + x) * 4;
      ls.push(0.2126 * img.px[i] + 0.7152 * img.px[i + 1] + 0.0722 * img.px[i + 2]);
    }
  }
  const dark = [...ls].sort((p, q) => p - q)[Math.floor(ls.length / 10)];
  return ls.filter((l) => l > dark + by).length / ls.length;
}

// The share of pixels of a region whose colour differs by more than `tol`
// in some channel.
function difference(a, b, [x0, y0, x1, y1] = [0, 0, a.width, a.height], tol = 24) {
  let n = 0, diff = 0;
  for (let y = y0; y < y1; y++) {
    for (let x = x0; x < x1; x++) {
      const i = (y * a.width + x) * 4;
      n++;
      if (Math.abs(a.px[i] - b.px[i]) > tol || Math.abs(a.px[i + 1] - b.px[i + 1]) > tol ||
        Math.abs(a.px[i + 2] - b.px[i + 2]) > tol) diff++;
    }
  }
  return diff / n;
}

// The scene `toml` with its BRDFs replaced by one of `model` with `params`
// (TOML lines), `view` maximised, the environment at `spp` samples per pixel.
function withOnlyBrdf(toml, model, params, spp, view = "environment") {
  const start = toml.indexOf("[[brdfs]]");
  const end = toml.indexOf("[incident]");
  const brdf = `[[brdfs]]\nid = 1\ncolor = [78, 151, 234]\nvisible = true\n\n` +
    `[brdfs.spec]\nmodel = "${model}"\n\n[brdfs.spec.params]\n${params.join("\n")}\n\n`;
  const one = toml.slice(0, start).replace(/^selected = .*$/m, "selected = 1").replace(/^next_id = .*$/m, "next_id = 2") +
    brdf + toml.slice(end);
  // The light at 45° (the copied link's is where the slider drag left it).
  return withMaximised(one.replace(/^target_spp = .*$/m, `target_spp = ${spp}`)
    .replace(/^theta_deg = .*$/m, "theta_deg = 45.0")
    .replace(/^object = .*$/m, 'object = "Sphere"'), view);
}

// Glass in the environment view on WebGPU (issue 33 part 5): a clear
// rough-dielectric sphere shows the studio through it, upside down (the
// floor at the top of the sphere, the bright wall at the bottom), where the
// studio behind it is bright above and dark below. The sphere's pixels are
// found from the same scene with a black Lambertian sphere. Without the
// paths through the object the sphere shows only its few per cent of
// reflection: dark, and not inverted.
async function glassInTheStudio(context, toml, base) {
  const area = [330, 50, W - 20, H - 50];
  // Few samples per pixel: the checks below are means over thousands of
  // pixels (the glass sphere at 16 spp still draws for a minute on a
  // software adapter; the black one needs one sample).
  const draw = async (model, params, name, view = "environment", spp = 16) => {
    const p = await open(context, linkOf(base, withOnlyBrdf(toml, model, params, spp, view)), name);
    await p.page.waitForTimeout(SETTLE_MS);
    const img = await shot(p.page, name);
    checkWebGpu(p, name, true);
    noErrors(p, name);
    await p.page.close();
    return img;
  };
  const glassParams = ["alpha_x = 0.05", "alpha_y = 0.05", 'distribution = "ggx"', "eta = 1.5",
    'geometry = "smith"', "tint = [1.0, 1.0, 1.0]"];
  // The polar view of the same glass is a full circle: its transmitted lobe
  // is drawn below the surface, in the BRDF's colour (78, 151, 234).
  {
    const polar = await draw("rough-dielectric", glassParams, "webgpu-polar-glass", "polar");
    let below = 0;
    const mid = Math.round((area[1] + area[3]) / 2);
    for (let y = mid + 20; y < area[3]; y++) {
      for (let x = area[0]; x < area[2]; x++) {
        const i = (y * W + x) * 4;
        const d = Math.abs(polar.px[i] - 78) + Math.abs(polar.px[i + 1] - 151) + Math.abs(polar.px[i + 2] - 234);
        if (d < 60) below++;
      }
    }
    check(below > 300, `glass on WebGPU: the polar view draws the transmitted lobe below the surface (${below} pixels)`);
  }
  const black = await draw("lambert", ["albedo = 0.0"], "webgpu-env-black-sphere", "environment", 1);
  const glass = await draw("rough-dielectric", glassParams, "webgpu-env-glass-sphere");
  const lum = (img, i) => 0.2126 * img.px[i] + 0.7152 * img.px[i + 1] + 0.0722 * img.px[i + 2];
  // The sphere: what the black sphere leaves black inside the view.
  let y0 = Infinity, y1 = -Infinity, n = 0;
  for (let y = area[1]; y < area[3]; y++) {
    for (let x = area[0]; x < area[2]; x++) {
      const i = (y * W + x) * 4;
      if (lum(black, i) < 3) { n++; y0 = Math.min(y0, y); y1 = Math.max(y1, y); }
    }
  }
  const share = n / ((area[2] - area[0]) * (area[3] - area[1]));
  check(share > 0.05, `environment view: the black sphere covers ${(100 * share).toFixed(1)}% of the view`);
  if (share <= 0.05) return;
  const cy = (y0 + y1) / 2;
  const mean = (img, upper, sphere) => {
    let s = 0, c = 0;
    for (let y = area[1]; y < area[3]; y++) {
      if ((y < cy) !== upper) continue;
      for (let x = area[0]; x < area[2]; x++) {
        const i = (y * W + x) * 4;
        if ((lum(black, i) < 3) === sphere) { s += lum(img, i); c++; }
      }
    }
    return s / Math.max(c, 1);
  };
  const [gUp, gDown] = [mean(glass, true, true), mean(glass, false, true)];
  const [bUp, bDown] = [mean(black, true, false), mean(black, false, false)];
  const through = (gUp + gDown) / Math.max(bUp + bDown, 1);
  check(through > 0.5,
    `glass on WebGPU: the studio is seen through the sphere (its mean luminance ${(100 * through).toFixed(0)}% of the studio's)`);
  check(bUp > bDown && gDown > gUp * 1.2,
    `glass on WebGPU: the studio seen through it is upside down (sphere top ${gUp.toFixed(0)} / bottom ${gDown.toFixed(0)}; ` +
    `studio top ${bUp.toFixed(0)} / bottom ${bDown.toFixed(0)})`);
}

// ---- the links (the same encoding as the Rust side: deflate, base64url) ----
function linkToml(url) {
  const frag = new URL(url).hash.replace(/^#/, "");
  const value = frag.split("&").find((kv) => kv.startsWith("scene=")).slice("scene=1.".length);
  return zlib.inflateRawSync(Buffer.from(value, "base64url")).toString("utf8");
}
function linkOf(base, toml) {
  return `${base}#scene=1.${zlib.deflateRawSync(Buffer.from(toml, "utf8")).toString("base64url")}`;
}
// The scene's TOML with `maximised` set to `view` (a top-level key: before
// the first table).
function withMaximised(toml, view) {
  const lines = toml.split("\n").filter((l) => !l.startsWith("maximised ="));
  const table = lines.findIndex((l) => l.startsWith("["));
  lines.splice(table, 0, `maximised = "${view}"`);
  return lines.join("\n");
}
// The view ids, in the order of the session's registry.
function viewIds() {
  const src = fs.readFileSync(path.join(here, "..", "src", "session", "views.rs"), "utf8");
  return [...src.matchAll(/^\s*id: "([a-z0-9_]+)",$/gm)].map((m) => m[1]);
}

// ---- a page of the viewer ----
async function open(context, url, what) {
  const page = await context.newPage();
  // Whole stacks in panic messages (Chromium keeps 10 frames by default).
  // The page's frames (requestAnimationFrame times) and bv's console lines
  // with their page times, for the checks that long work keeps it drawing.
  await page.addInitScript(() => {
    Error.stackTraceLimit = 60;
    window.__bvFrames = [];
    const tick = (t) => {
      window.__bvFrames.push(t);
      requestAnimationFrame(tick);
    };
    requestAnimationFrame(tick);
    // The page's WebGPU devices, for the check that destroys them (wgpu
    // keeps its own handle inside the module).
    window.__bvDevices = [];
    if (window.GPUAdapter) {
      const request = GPUAdapter.prototype.requestDevice;
      GPUAdapter.prototype.requestDevice = async function (...a) {
        const device = await request.apply(this, a);
        window.__bvDevices.push(device);
        return device;
      };
    }
    window.__bvLog = [];
    const info = console.info.bind(console);
    console.info = (...a) => {
      window.__bvLog.push([performance.now(), String(a[0])]);
      info(...a);
    };
  });
  const log = [];
  const errors = [];
  page.on("console", (m) => {
    const text = m.text();
    log.push(text);
    if (m.type() === "error") errors.push(text);
  });
  page.on("pageerror", (e) => errors.push(String(e)));
  const t0 = Date.now();
  await page.goto(url);
  // The first frame; if WebGPU is lost the page reloads on WebGL2 and the
  // frame that counts is the one after the reload.
  let firstFrame = null;
  let settled = null;
  let seen = 0;
  while (Date.now() - t0 < FIRST_FRAME_TIMEOUT && !errors.length) {
    const frames = log.filter((l) => l === "bv: first frame").length;
    const reloads = log.filter((l) => l.includes("reloading on WebGL2")).length;
    if (frames > 0 && firstFrame === null) firstFrame = Date.now() - t0;
    if (frames !== seen) {
      seen = frames;
      settled = Date.now();
    }
    // A WebGPU device may be lost a few seconds after its first present:
    // on WebGPU wait longer before calling the page settled.
    const renderers = log.filter((l) => l.startsWith("bv: renderer"));
    const quiet = /BrowserWebGpu/.test(renderers[renderers.length - 1] || "") ? 6000 : 1500;
    if (frames > reloads && Date.now() - settled > quiet) break;
    await page.waitForTimeout(50);
  }
  const reloaded = log.some((l) => l.includes("reloading on WebGL2"));
  // Why, in bv's words ("WebGPU was lost (Unknown: …)"), for the CI log.
  const lost = lostReason(log);
  check(firstFrame !== null, `${what}: first frame${firstFrame !== null ? ` after ${firstFrame} ms` : ""}` +
    (reloaded ? ` (${lost}: reloaded on WebGL2)` : ""));
  return { page, log, errors, firstFrame, reloaded };
}
// The reason a page gave for losing its WebGPU device, if it lost it.
function lostReason(log) {
  const l = log.find((t) => t.startsWith("bv: WebGPU was lost"));
  return l ? l.slice("bv: ".length).replace(/; reloading on WebGL2$/, "") : null;
}
// The renderer a page draws with now (its last `bv: renderer` line: a page
// that lost WebGPU says it again after its reload).
function rendererOf(log) {
  return [...log].reverse().find((l) => l.startsWith("bv: renderer")) || "(no renderer line)";
}
// Whether a page is on WebGPU now: its renderer is the browser's WebGPU and
// it has not lost the device (a loss is noted before the reload).
function onWebGpu(p) {
  return /^bv: renderer BrowserWebGpu/.test(rendererOf(p.log)) && !lostReason(p.log);
}
// A screenshot waits for a frame of the page. On WebGPU in software the
// environment view accumulates its samples in frames of a second and more
// for the first tens of seconds of a page (SwiftShader is taken for a GPU:
// the browser does not call it a fallback adapter), and a screenshot then
// waits as long: first the page is let finish (the browser's frames come
// freely again, up to IDLE_MS), so that the picture is the finished one.
const IDLE_MS = 120_000;
async function idle(page) {
  const t0 = Date.now();
  while (Date.now() - t0 < IDLE_MS) {
    // (A page that reloads meanwhile, on a lost device, is not idle yet.)
    const free = await page.evaluate(() => {
      const now = performance.now();
      return window.__bvFrames ? window.__bvFrames.filter((t) => t > now - 1000).length >= 30 : true;
    }).catch(() => false);
    if (free) break;
    await page.waitForTimeout(250);
  }
  return Date.now() - t0;
}
async function shot(page, name) {
  const waited = await idle(page);
  if (waited > 10_000) console.log(`     (${name}: the page drew for ${(waited / 1000).toFixed(0)} s more before it was idle)`);
  const buf = await page.screenshot({ path: path.join(shots, `${name}.png`), timeout: IDLE_MS });
  return decodePng(buf);
}
function notBlank(img, what, region) {
  const s = stats(img, region);
  check(s.colours > 30 && s.std > 8, `${what}: not blank (${s.colours} colours, luminance spread ${s.std.toFixed(1)})`);
}
function noErrors(p, what) {
  check(p.errors.length === 0, `${what}: no console error${p.errors.length ? `: ${p.errors.slice(0, 3).join(" | ")}` : ""}`);
}

// Finds the line a `bv: link …` message put in the console.
function lastLink(log) {
  const l = [...log].reverse().find((t) => t.startsWith("bv: link "));
  return l && l.slice("bv: link ".length);
}

// Waits until some console line satisfies `pred` (at most `ms`).
async function waitLog(p, pred, ms = 60_000) {
  const t0 = Date.now();
  while (Date.now() - t0 < ms && !p.log.some(pred) && !p.errors.length) await p.page.waitForTimeout(50);
  return p.log.find(pred);
}

// The frames drawn while the page's first background work after page time
// `since` ran: the job's length, the frames in it and the longest gap
// between two of them (ms), and the page's own count of steps.
async function framesDuringWork(p, since) {
  const t0 = Date.now();
  let w = null;
  while (Date.now() - t0 < 120_000 && !p.errors.length) {
    w = await p.page.evaluate((since) => {
      const log = window.__bvLog;
      const start = log.find(([t, l]) => l === "bv: background work started" && t >= since);
      const end = start && log.find(([t, l]) => l.startsWith("bv: background work finished") && t >= start[0]);
      if (!end) return null;
      const f = window.__bvFrames.filter((t) => t >= start[0] && t <= end[0]);
      const edges = [start[0], ...f, end[0]];
      let gap = 0;
      for (let i = 1; i < edges.length; i++) gap = Math.max(gap, edges[i] - edges[i - 1]);
      return { ms: end[0] - start[0], frames: f.length, gap, steps: end[1].replace(/^.*\(|\)$/g, "") };
    }, since);
    if (w) break;
    await p.page.waitForTimeout(100);
  }
  return w;
}

// Drops files ({name, base64}) on the canvas.
async function drop(page, files) {
  const dt = await page.evaluateHandle((files) => {
    const d = new DataTransfer();
    for (const f of files) {
      const bytes = Uint8Array.from(atob(f.base64), (c) => c.charCodeAt(0));
      d.items.add(new File([bytes], f.name));
    }
    return d;
  }, files);
  await page.dispatchEvent("#bv_canvas", "dragover", { dataTransfer: dt });
  await page.dispatchEvent("#bv_canvas", "drop", { dataTransfer: dt });
}

// A small MERL table (θh × θd × φd cells, three channels of doubles after
// a header of three int32 dimensions): a lobe that falls off with θh.
function merlTable(nh = 8, nd = 8, np = 16) {
  const cells = nh * nd * np;
  const buf = Buffer.alloc(12 + 24 * cells);
  buf.writeInt32LE(nh, 0);
  buf.writeInt32LE(nd, 4);
  buf.writeInt32LE(np, 8);
  const tint = [1.0, 0.6, 0.3];
  for (let c = 0; c < 3; c++) {
    for (let i = 0; i < cells; i++) {
      const ih = Math.floor(i / (nd * np));
      buf.writeDoubleLE(1500 * tint[c] * (0.05 + 3 * Math.exp(-1.5 * ih)), 12 + 8 * (c * cells + i));
    }
  }
  return buf;
}

// A .brdf model of our own (Disney's format, GLSL): a tinted Lambertian
// with a sharp Phong lobe.
const BRDF_FILE = `analytic
# A test model: tinted Lambert plus a Phong lobe.
::begin parameters
color tint 0.9 0.2 0.1
float shininess 1 200 40
::end parameters
::begin shader
vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)
{
    vec3 R = reflect(-L, N);
    float s = pow(max(dot(R, V), 0.0), shininess);
    return tint / 3.14159265 + vec3(s * (shininess + 2.0) / 6.2831853);
}
::end shader
`;

async function run() {
  if (!fs.existsSync(path.join(dist, "bv_bg.wasm"))) throw new Error(`no bundle in ${dist}: run web/build.sh`);
  const wasmBytes = fs.statSync(path.join(dist, "bv_bg.wasm")).size;
  const jsBytes = fs.statSync(path.join(dist, "bv.js")).size;
  console.log(`bundle: bv_bg.wasm ${(wasmBytes / 1048576).toFixed(1)} MiB, bv.js ${(jsBytes / 1024).toFixed(0)} KiB, ` +
    `gzipped wasm ${(zlib.gzipSync(fs.readFileSync(path.join(dist, "bv_bg.wasm"))).length / 1048576).toFixed(1)} MiB`);
  const server = await serve();
  const base = `http://127.0.0.1:${server.address().port}/`;
  const executablePath = process.env.CHROMIUM || "/usr/bin/chromium";
  const launch = (webgpu) => chromium.launch({
    executablePath,
    headless: true,
    args: ["--no-sandbox", ...(webgpu ? WEBGPU_ARGS : [])],
  });
  try {
    if (!webglOnly) {
      const browser = await launch(true);
      console.log(`     WebGPU browser: ${WEBGPU_ARGS.join(" ")}`);
      const context = await browser.newContext({ viewport: { width: W, height: H } });
      const keeps = await probeWebGpu(context, base);
      await webgpuChecks(context, base, keeps);
      await browser.close();
    }
    const browser = await launch(false);
    const context = await browser.newContext({ viewport: { width: W, height: H } });
    await webglChecks(context, base);
    await browser.close();
  } finally {
    server.close();
  }
}

// The slider dragged: the light's θi slider in the left panel (at 1280x800
// in the first-run scene: its knob at x = 62 on the row y = 183; egui draws
// no DOM to find it by).
const SLIDER = { y: 183, x0: 62, x1: 112 };
// The Copy link button, at the window's bottom right corner, and Save scene
// left of it.
const COPY_LINK = { x: W - 42, y: H - 18 };
const SAVE_SCENE = { x: W - 120, y: H - 18 };
// A frame gap that says the page was blocked: software rendering of the
// dev build draws a busy view's frame in a few hundred milliseconds; a
// computation done in one go blocks it for seconds.
const MAX_FRAME_GAP = 1500;
// The longest step of background work allowed (the page runs steps for
// turns of 50–250 ms between frames; a step should not take much longer
// than a frame of the dev build under software rendering).
const MAX_STEP_MS = 400;

// Whether this browser keeps a WebGPU device that presents to a canvas, on
// a page of a few lines without bv (PROBE_HTML); says which case applies.
async function probeWebGpu(context, base) {
  const page = await context.newPage();
  await page.goto(base + PROBE_PAGE);
  const r = await page.evaluate(() => window.__probe).catch((e) => ({ adapter: null, why: String(e) }));
  await page.close();
  let keeps = false;
  if (!r.adapter) {
    console.log(`     WebGPU probe: no WebGPU device for a minimal page (${r.why}): ` +
      "the WebGPU page may draw on WebGL2");
  } else if (r.lost) {
    console.log(`     WebGPU probe: a minimal page on ${r.adapter} LOST its device after ${r.frames} frames ` +
      `(${r.lost}): the browser does not keep WebGPU here, so the WebGPU page is only required to fall back ` +
      "to WebGL2");
  } else {
    keeps = true;
    console.log(`     WebGPU probe: a minimal page on ${r.adapter} kept its device for ${r.ms} ms ` +
      `(${r.frames} frames presented): the WebGPU page must stay on WebGPU`);
  }
  return keeps;
}

// The checks of a page that must be on WebGPU where the browser keeps a
// device (`keeps`): its renderer, and no loss (whose reason is printed).
function checkWebGpu(p, what, keeps) {
  if (!keeps) return;
  const lost = lostReason(p.log);
  check(onWebGpu(p), `${what}: on WebGPU (${rendererOf(p.log).slice("bv: ".length)}` +
    `${lost ? `; ${lost}` : ""})`);
}

async function webgpuChecks(context, base, keeps) {
  const a = await open(context, base, "WebGPU page");
  const renderers = a.log.filter((l) => l.startsWith("bv: renderer"));
  console.log(`     ${renderers.join(" | then ")}`);
  check(/BrowserWebGpu/.test(renderers[0] || ""), "WebGPU page: WebGPU adapter and device");
  // The bundle is built with WebAssembly SIMD (.cargo/config.toml): the lobe
  // mesh and slices run bv-core's simd128 kernels, not the scalar fallback.
  const kernels = a.log.find((l) => l.startsWith("bv: batch kernels")) || "(no line)";
  check(kernels === "bv: batch kernels simd128 (4 lanes)", `WebGPU page: batch kernels on WebAssembly SIMD: ${kernels}`);
  if (!keeps) {
    // A browser that takes the device back (the probe's page lost it too):
    // the page must notice and carry on with WebGL2.
    check(!a.reloaded || /Gl/.test(renderers[renderers.length - 1] || ""),
      `WebGPU page: a lost device falls back to WebGL2 (${lostReason(a.log) || "not lost"})`);
  }
  await a.page.waitForTimeout(SETTLE_MS);
  const first = await shot(a.page, "webgpu-first");
  // The browser keeps a device (the probe's page did): so must bv's page,
  // once it has settled (its first work drawn: the screenshot waits for it).
  checkWebGpu(a, "WebGPU page, settled", keeps);
  notBlank(first, "WebGPU page");
  noErrors(a, "WebGPU page");

  // A slider dragged through the canvas changes the picture.
  const s = SLIDER;
  await a.page.mouse.move(s.x0, s.y);
  await a.page.mouse.down();
  await a.page.mouse.move((s.x0 + s.x1) / 2, s.y, { steps: 8 });
  await a.page.mouse.move(s.x1, s.y, { steps: 8 });
  await a.page.mouse.up();
  await a.page.mouse.move(W / 2, 8);
  await a.page.waitForTimeout(SETTLE_MS);
  const dragged = await shot(a.page, "webgpu-dragged");
  const moved = difference(first, dragged, [300, 0, W, H]);
  check(moved > 0.01, `slider drag changes the views (${(100 * moved).toFixed(1)}% of the pixels)`);

  // Copy link, then open it: the same picture.
  await a.page.mouse.click(COPY_LINK.x, COPY_LINK.y);
  let link = null;
  for (let i = 0; i < 100 && !link; i++) {
    await a.page.waitForTimeout(50);
    link = lastLink(a.log);
  }
  check(!!link && link.startsWith(base + "#scene=1."), `Copy link gives a link (${link ? link.length : 0} characters)`);
  const href = await a.page.evaluate(() => location.href);
  check(href === link, "Copy link puts the link into the address bar");
  // Let "Link copied" turn back into "Copy link".
  await a.page.waitForTimeout(Math.max(SETTLE_MS, 2500));
  const before = await shot(a.page, "webgpu-before-link");
  noErrors(a, "WebGPU page after the drag and Copy link");
  if (!link) return;
  const b = await open(context, link, "the copied link");
  check(b.log.some((l) => l.startsWith("bv: opened the scene of the link")), "the copied link opens its scene");
  await b.page.waitForTimeout(SETTLE_MS);
  const after = await shot(b.page, "webgpu-link-opened");
  const d = difference(before, after);
  check(d < 0.02, `the link reproduces the scene (${(100 * d).toFixed(2)}% of the pixels differ)`);
  checkWebGpu(b, "the copied link", keeps);
  noErrors(b, "the copied link");
  await b.page.close();

  // Every view, maximised through a link made from the copied one: on
  // WebGPU where the browser keeps a device, else asking for WebGL2 at once
  // (`?webgl`; the WebGPU attempt and its reload were checked above and
  // would only cost time here).
  const toml = linkToml(link);
  const gl = `${base}?webgl`;
  for (const view of viewIds()) {
    // The environment view maximised, at the scene's 1024 samples per
    // pixel, draws for minutes on a software adapter: 64 show it as well.
    const scene = view === "environment" ? toml.replace(/^target_spp = .*$/m, "target_spp = 64") : toml;
    const p = await open(context, linkOf(keeps ? base : gl, withMaximised(scene, view)), `view ${view}`);
    await p.page.waitForTimeout(SETTLE_MS);
    // A view whose work still runs (the factorisation: a minute of steps in
    // the dev build under software rendering) is drawn once it is done.
    if (p.log.includes("bv: background work started")) await framesDuringWork(p, 0);
    // The view's area: right of the panel, below the menu.
    const img = await shot(p.page, `webgpu-view-${view}`);
    notBlank(img, `view ${view}`, [320, 40, W - 10, H - 40]);
    // The lit sphere is drawn (on the CPU where the page got WebGL2), not
    // only labelled.
    if (view === "lit_sphere") {
      const share = brightShare(img, [370, 70, W - 20, H - 40]);
      check(share > 0.05, `view lit_sphere: a lit sphere is drawn (${(100 * share).toFixed(1)}% of the view lit)`);
    }
    // The environment view draws only on WebGPU (WebGL2 gets a line of
    // text saying it needs WebGPU): the objects in the environment, not
    // a dark area with a caption.
    if (view === "environment" && keeps) {
      const area = [370, 70, W - 20, H - 40];
      const share = brightShare(img, area, 20);
      const c = stats(img, area).colours;
      check(share > 0.05 && c > 1000,
        `view environment: drawn on WebGPU (${(100 * share).toFixed(1)}% of the view lit, ${c} colours)`);
    }
    checkWebGpu(p, `view ${view}`, keeps);
    noErrors(p, `view ${view}`);
    await p.page.close();
  }
  if (keeps) await glassInTheStudio(context, toml, base);
  if (keeps) await forcedLoss(context, toml, base);

  // A scene file dropped on the page opens.
  {
    const p = await open(context, gl, "a page a scene file is dropped on");
    const dt = await p.page.evaluateHandle((text) => {
      const d = new DataTransfer();
      d.items.add(new File([text], "dropped.toml", { type: "application/toml" }));
      return d;
    }, withMaximised(toml, "polar"));
    await p.page.dispatchEvent("#bv_canvas", "dragover", { dataTransfer: dt });
    await p.page.dispatchEvent("#bv_canvas", "drop", { dataTransfer: dt });
    for (let i = 0; i < 100 && !p.log.some((l) => l.startsWith("bv: opened the scene file")); i++) {
      await p.page.waitForTimeout(50);
    }
    check(p.log.some((l) => l === "bv: opened the scene file dropped.toml"), "a dropped scene file opens");
    await p.page.waitForTimeout(SETTLE_MS);
    notBlank(await shot(p.page, "webgpu-dropped-scene"), "the dropped scene");
    noErrors(p, "a page a scene file is dropped on");
    await p.page.close();
  }

  // The session persists: a page without a link starts from the stored
  // state (θi as dragged; the views' pages above saved theirs meanwhile).
  {
    const p = await open(context, gl, "a page without a link");
    await p.page.waitForTimeout(SETTLE_MS);
    const stored = await p.page.evaluate(() => localStorage.getItem("bv-state") || "");
    check(stored.length > 0, `the session is in local storage (${stored.length} characters)`);
    const light = [0, 150, 340, 230];
    const d = difference(before, await shot(p.page, "webgpu-restored"), light);
    check(d < 0.01, `the stored session restores the light (${(100 * d).toFixed(2)}% of the panel's light rows differ)`);
    noErrors(p, "a page without a link");
    await p.page.close();
  }

  // Hostile fragments: a message and the default scene.
  const hostile = {
    garbage: "#scene=1.!!!%%%",
    version: "#scene=7.AAAA",
    nonsense: `#scene=1.${Buffer.from("not a scene at all, just bytes").toString("base64url")}`,
    huge: `#scene=1.${"A".repeat(100_000)}`,
    bomb: `#scene=1.${zlib.deflateRawSync(Buffer.alloc(16 << 20, 32)).toString("base64url")}`,
  };
  for (const [name, frag] of Object.entries(hostile)) {
    const p = await open(context, gl + frag, `hostile fragment (${name})`);
    check(p.log.some((l) => l.startsWith("bv: refused the link")),
      `hostile fragment (${name}) is refused: ${(p.log.find((l) => l.startsWith("bv: refused")) || "").slice(0, 100)}`);
    await p.page.waitForTimeout(SETTLE_MS);
    const img = await shot(p.page, `webgpu-hostile-${name}`);
    notBlank(img, `hostile fragment (${name})`);
    // The default scene: the left panel as on the first page.
    const d = difference(first, img, [0, 0, 350, H]);
    check(d < 0.01, `hostile fragment (${name}) shows the default scene (${(100 * d).toFixed(2)}% of the panel differs)`);
    noErrors(p, `hostile fragment (${name})`);
    await p.page.close();
  }
  // The first page was open all along (its device for a minute and more):
  // what it draws with at the end.
  console.log(`     WebGPU page at the end: ${rendererOf(a.log).slice("bv: ".length)}` +
    `${lostReason(a.log) ? ` (${lostReason(a.log)})` : ""}`);
  checkWebGpu(a, "WebGPU page at the end of the WebGPU checks", keeps);
  await a.page.close();

  // After the session check: these pages store sessions of their own.
  await longWorkChecks(context, gl, toml);
  await downloadChecks(context, gl, toml);
  await openFileChecks(context, gl, toml);
  await fileChooserChecks(context, gl, toml);
}

// A device lost while the page draws: destroyed from the page itself (the
// devices wgpu asked the browser for, kept by the init script of `open`),
// the page notes the loss with its reason and reloads on WebGL2, with the
// scene of its link, and draws there.
async function forcedLoss(context, toml, base) {
  const p = await open(context, linkOf(base, withMaximised(toml, "lit_sphere")), "a page whose device is destroyed");
  checkWebGpu(p, "a page whose device is destroyed, before", true);
  const destroyed = await p.page.evaluate(() => {
    for (const d of window.__bvDevices) d.destroy();
    return window.__bvDevices.length;
  });
  const gl = await waitLog(p, (l) => /^bv: renderer Gl/.test(l), 30_000);
  const lost = lostReason(p.log);
  check(destroyed > 0 && !!lost && !!gl,
    `a destroyed device (${destroyed} destroyed) falls back to WebGL2: ${lost || "no loss noted"}; ` +
    `then ${gl ? gl.slice("bv: ".length) : "no WebGL2 renderer in 30 s"}`);
  // After the reload: the first frame on WebGL2, then the picture.
  const frames = () => p.log.filter((l) => l === "bv: first frame").length;
  for (const t0 = Date.now(); Date.now() - t0 < 30_000 && frames() < 2;) await p.page.waitForTimeout(50);
  await p.page.waitForTimeout(SETTLE_MS);
  const img = await shot(p.page, "webgpu-destroyed-then-webgl");
  const share = brightShare(img, [370, 70, W - 20, H - 40]);
  check(share > 0.05, `after the loss, the lit sphere is drawn on WebGL2 (${(100 * share).toFixed(1)}% of the view lit)`);
  await p.page.close();
}

// Ctrl+O (and the Open… button) open the browser's file chooser; the file
// chosen there opens as a dropped one does.
async function fileChooserChecks(context, gl, toml) {
  const p = await open(context, linkOf(gl, toml), "a page a scene is chosen on");
  await p.page.waitForTimeout(SETTLE_MS);
  const before = await shot(p.page, "webgl-chooser-before");
  const chooser = p.page.waitForEvent("filechooser", { timeout: 30_000 });
  // The keys go to the focused element: the canvas, as after a click on it.
  await p.page.focus("#bv_canvas");
  const pressed = Date.now();
  await p.page.keyboard.press("Control+O");
  try {
    const c = await chooser.catch((e) => {
      // Which half failed: bv did not take the key, or the browser did not
      // show the chooser it asked for (a user activation expires in 5 s).
      const asked = p.log.includes("bv: file chooser opened");
      throw new Error(`${asked ? "bv asked for the chooser but the browser showed none" : "bv did not take Ctrl+O"} ` +
        `(${Date.now() - pressed} ms after the key): ${e.message.split("\n")[0]}`);
    });
    console.log(`     the chooser opened ${Date.now() - pressed} ms after the key`);
    check(c.isMultiple(), "Ctrl+O opens the browser's file chooser (several files allowed)");
    await c.setFiles({
      name: "chosen.toml",
      mimeType: "application/toml",
      buffer: Buffer.from(withMaximised(toml, "polar")),
    });
    check(!!await waitLog(p, (l) => l === "bv: opened the scene file chosen.toml", 10_000),
      "the scene chosen in the file chooser opens");
    await p.page.waitForTimeout(SETTLE_MS);
    const after = await shot(p.page, "webgl-chooser-opened");
    notBlank(after, "the chosen scene");
    const d = difference(before, after, [320, 40, W - 10, H - 40]);
    check(d > 0.05, `the chosen scene (the polar view maximised) is drawn (${(100 * d).toFixed(1)}% of the pixels changed)`);
  } catch (e) {
    check(false, `Ctrl+O opens the browser's file chooser: ${e}`);
  }
  noErrors(p, "a page a scene is chosen on");
  await p.page.close();
}

// Long computations run in steps between frames: the page keeps drawing
// while the albedo curves, the sampling histogram and the factorisation are
// computed. Each view is maximised on a page of its own; once the page has
// settled (its start-up work done), a scene with another light azimuth and
// albedo is dropped on it, which starts the view's work afresh.
async function longWorkChecks(context, gl, toml) {
  const changed = toml.replace(/^phi_deg = .*$/m, "phi_deg = 40.0")
    .replace(/^albedo = .*$/m, "albedo = [0.7, 0.6, 0.5]");
  // (The factorisation view's work, in 1585 steps, takes a minute in the
  // dev build under software rendering: too long for CI.)
  for (const view of ["albedo", "sampling"]) {
    const p = await open(context, linkOf(gl, withMaximised(toml, view)), `long work (${view})`);
    await framesDuringWork(p, 0);
    await p.page.waitForTimeout(1000);
    const since = await p.page.evaluate(() => performance.now());
    await drop(p.page, [{ name: "changed.toml", base64: Buffer.from(withMaximised(changed, view)).toString("base64") }]);
    const w = await framesDuringWork(p, since);
    check(!!w, `long work (${view}): background work started and finished`);
    if (w) {
      console.log(`     ${view}: ${w.ms.toFixed(0)} ms of work (${w.steps}), ${w.frames} frames meanwhile, ` +
        `longest gap ${w.gap.toFixed(0)} ms`);
      // The page's own count: many short steps, not one long one. Then the
      // browser's frames: a computation done in one go would leave a gap as
      // long as itself.
      const [, steps, longest] = (w.steps.match(/^(\d+) steps, the longest (\d+) ms$/) || []).map(Number);
      check(steps >= 10 && longest <= MAX_STEP_MS,
        `long work (${view}): done in ${steps} steps of at most ${longest} ms`);
      check(w.gap < MAX_FRAME_GAP, `long work (${view}): frames keep coming (longest gap ${w.gap.toFixed(0)} ms)`);
    }
    await p.page.waitForTimeout(500);
    notBlank(await shot(p.page, `webgl-work-${view}`), `long work (${view}) result`, [320, 40, W - 10, H - 40]);
    noErrors(p, `long work (${view})`);
    await p.page.close();
  }
}

// Scenes and figures are saved as downloads.
async function downloadChecks(context, gl, toml) {
  const p = await open(context, linkOf(gl, toml), "a page that saves downloads");
  await p.page.waitForTimeout(SETTLE_MS);
  // Save scene (bottom right, beside Copy link).
  {
    const download = p.page.waitForEvent("download", { timeout: 30_000 });
    await p.page.mouse.click(SAVE_SCENE.x, SAVE_SCENE.y);
    try {
      const d = await download;
      const file = path.join(shots, "downloaded-scene.toml");
      await d.saveAs(file);
      const text = fs.readFileSync(file, "utf8");
      check(text.includes("[[brdfs]]") && text.trimEnd().endsWith("# end of bv scene"),
        `the scene downloads as a whole scene file (${text.length} characters)`);
    } catch (e) {
      check(false, `the scene downloads: ${e}`);
    }
  }
  // Export figure (Ctrl+Shift+S opens the dialog, Enter saves): a PNG of
  // the whole window, whose pixels a page can only read back between frames.
  {
    const download = p.page.waitForEvent("download", { timeout: 60_000 });
    await p.page.keyboard.press("Control+Shift+S");
    await p.page.waitForTimeout(500);
    await p.page.keyboard.press("Enter");
    try {
      const d = await download;
      const file = path.join(shots, "downloaded-figure.png");
      await d.saveAs(file);
      const img = decodePng(fs.readFileSync(file));
      check(img.width >= W && img.height >= H,
        `the window figure downloads as a PNG (${img.width}×${img.height} px, ${d.suggestedFilename()})`);
      notBlank(img, "the downloaded window figure");
    } catch (e) {
      check(false, `the window figure downloads as a PNG: ${e}`);
    }
  }
  noErrors(p, "a page that saves downloads");
  await p.page.close();
}

// Files dropped on the page open: a MERL table, an RGL material, a .brdf
// model, an environment map.
async function openFileChecks(context, gl, toml) {
  const p = await open(context, linkOf(gl, withMaximised(toml, "polar")), "a page files are opened on");
  await p.page.waitForTimeout(SETTLE_MS);
  let before = await shot(p.page, "webgl-files-before");
  const brdfs = () => Number((p.log.filter((l) => /^bv: \d+ BRDFs$/.test(l)).pop() || "0").match(/\d+/)[0]);
  const opened = async (name, files, what) => {
    const n = brdfs();
    await drop(p.page, files);
    await waitLog(p, (l) => l.startsWith(`bv: opening the file ${name}`), 10_000);
    const t0 = Date.now();
    while (Date.now() - t0 < 30_000 && brdfs() === n &&
      !p.log.some((l) => l.startsWith(`bv: could not open ${name}`))) await p.page.waitForTimeout(50);
    const failed = p.log.find((l) => l.startsWith(`bv: could not open ${name}`));
    check(brdfs() === n + 1 && !failed, `${what} opens as a BRDF (${n} → ${brdfs()})${failed ? `: ${failed}` : ""}`);
    await p.page.waitForTimeout(SETTLE_MS);
    const after = await shot(p.page, `webgl-files-${name}`);
    const d = difference(before, after, [320, 40, W - 10, H - 40]);
    check(d > 0.005, `${what} changes the picture (${(100 * d).toFixed(1)}% of the pixels)`);
    before = after;
  };
  await opened("test.binary", [{ name: "test.binary", base64: merlTable().toString("base64") }],
    "a dropped MERL table");
  await opened("phong.brdf", [{ name: "phong.brdf", base64: Buffer.from(BRDF_FILE).toString("base64") }],
    "a dropped .brdf model");
  // Hostile .brdf files (tests/data/brdf/hostile/: a 7,000-term sum and
  // 6,000 nested parentheses that overflowed the stack, macros that double
  // 40 times) are refused on the status line with their reason, each within
  // seconds; a shader that loops away from the normal compiles and is added
  // with its build error. The page goes on: the next good file still opens.
  for (const [name, why] of [["long_sum.brdf", "operators"], ["deep_parentheses.brdf", "nest"],
    ["doubling_defines.brdf", "operators"]]) {
    const bytes = fs.readFileSync(path.join(here, "..", "tests", "data", "brdf", "hostile", name));
    const n = brdfs();
    await drop(p.page, [{ name, base64: bytes.toString("base64") }]);
    const refused = await waitLog(p, (l) => l.startsWith("bv: status:") && l.includes(name) && l.includes(why), 15_000);
    const said = p.log.slice(-6).join(" | ");
    check(!!refused && brdfs() === n,
      `a dropped hostile ${name} is refused${refused ? `: ${refused.slice(0, 160)}` : ` (no such status in 15 s; last: ${said.slice(0, 300)})`}`);
  }
  {
    const name = "loop_away_from_normal.brdf";
    const bytes = fs.readFileSync(path.join(here, "..", "tests", "data", "brdf", "hostile", name));
    const n = brdfs();
    await drop(p.page, [{ name, base64: bytes.toString("base64") }]);
    const t0 = Date.now();
    while (Date.now() - t0 < 15_000 && brdfs() === n) await p.page.waitForTimeout(50);
    check(brdfs() === n + 1, `a dropped ${name} is added (with its build error) within 15 s`);
  }
  await opened("phong2.brdf", [{ name: "phong2.brdf", base64: Buffer.from(BRDF_FILE).toString("base64") }],
    "a .brdf model dropped after the hostile ones");
  // An RGL material (.bsdf tensor file, issue 34), written by the desktop
  // binary (BV_BIN, which .ci/web.sh finds or builds): a sharp GGX lobe
  // (α 0.05, its peak rescales the plot) over a blue base, tabulated as the
  // RGL database stores materials.
  {
    const bin = process.env.BV_BIN;
    const file = path.join(fs.mkdtempSync(path.join(os.tmpdir(), "bv-web-")), "ggx.bsdf");
    let bytes = null;
    try {
      execFileSync(bin || "bv", ["tabulate", "--format", "rgl", "-m", "cook-torrance", "-p", "distribution=ggx",
        "-p", "alpha=0.05", "-p", "kd=0.05,0.1,0.4", "-p", "ks=1", "--out", file], { stdio: "ignore" });
      bytes = fs.readFileSync(file);
    } catch (e) {
      check(false, `an RGL file is written for the drop (BV_BIN=${bin}): ${e}`);
    }
    if (bytes) await opened("ggx.bsdf", [{ name: "ggx.bsdf", base64: bytes.toString("base64") }], "a dropped RGL material");
  }
  {
    const hdr = fs.readFileSync(path.join(here, "..", "assets", "studio.hdr"));
    await drop(p.page, [{ name: "studio.hdr", base64: hdr.toString("base64") }]);
    check(!!await waitLog(p, (l) => l === "bv: opened the environment map studio.hdr", 10_000),
      "a dropped environment map is taken");
  }
  await p.page.waitForTimeout(SETTLE_MS);
  notBlank(await shot(p.page, "webgl-files-opened"), "the page with the opened files");
  noErrors(p, "a page files are opened on");
  await p.page.close();
}

async function webglChecks(context, base) {
  const a = await open(context, base, "WebGL2 page");
  const renderer = a.log.find((l) => l.startsWith("bv: renderer"));
  console.log(`     ${renderer}`);
  check(/^bv: renderer Gl/.test(renderer || ""), "WebGL2 page: WebGL2 renderer");
  await a.page.waitForTimeout(SETTLE_MS);
  notBlank(await shot(a.page, "webgl-first"), "WebGL2 page");
  noErrors(a, "WebGL2 page");
  await a.page.close();
}

run().then(
  () => {
    console.log(failures ? `${failures} check(s) failed` : "all web checks passed");
    process.exit(failures ? 1 : 0);
  },
  (e) => {
    console.error(e);
    process.exit(1);
  },
);
