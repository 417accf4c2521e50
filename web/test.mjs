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
// session persists in local storage, and hostile fragments fall back to the
// default scene with a message. Then the
// first-frame checks again with WebGPU off (WebGL2 only). Screenshots go to
// web/shots (or --shots DIR); timings and the renderer are printed.
import { chromium } from "playwright-core";
import http from "node:http";
import fs from "node:fs";
import path from "node:path";
import zlib from "node:zlib";
import { fileURLToPath } from "node:url";

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

fs.mkdirSync(shots, { recursive: true });
let failures = 0;
function check(ok, what) {
  console.log(`${ok ? "ok  " : "FAIL"} ${what}`);
  if (!ok) failures++;
}

// ---- a static server for the bundle ----
const types = {
  ".html": "text/html; charset=utf-8",
  ".js": "text/javascript; charset=utf-8",
  ".wasm": "application/wasm",
};
function serve() {
  const server = http.createServer((req, res) => {
    const url = new URL(req.url, "http://localhost");
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
  await page.addInitScript(() => {
    Error.stackTraceLimit = 60;
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
  check(firstFrame !== null, `${what}: first frame${firstFrame !== null ? ` after ${firstFrame} ms` : ""}` +
    (reloaded ? " (WebGPU lost: reloaded on WebGL2)" : ""));
  return { page, log, errors, firstFrame, reloaded };
}
async function shot(page, name) {
  const buf = await page.screenshot({ path: path.join(shots, `${name}.png`) });
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
    args: ["--no-sandbox", ...(webgpu ? ["--enable-unsafe-webgpu"] : [])],
  });
  try {
    if (!webglOnly) {
      const browser = await launch(true);
      const context = await browser.newContext({ viewport: { width: W, height: H } });
      await webgpuChecks(context, base);
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
// The Copy link button, at the window's bottom right corner.
const COPY_LINK = { x: W - 42, y: H - 18 };

async function webgpuChecks(context, base) {
  const a = await open(context, base, "WebGPU page");
  const renderers = a.log.filter((l) => l.startsWith("bv: renderer"));
  console.log(`     ${renderers.join(" | then ")}`);
  check(/BrowserWebGpu/.test(renderers[0] || ""), "WebGPU page: WebGPU adapter and device");
  // Headless Chromium on SwiftShader destroys the WebGPU device at its first
  // canvas present (plain JavaScript does the same): the page must notice
  // and carry on with WebGL2.
  check(!a.reloaded || /Gl/.test(renderers[renderers.length - 1] || ""),
    "WebGPU page: a lost device falls back to WebGL2");
  await a.page.waitForTimeout(SETTLE_MS);
  const first = await shot(a.page, "webgpu-first");
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
  noErrors(b, "the copied link");
  await b.page.close();

  // Every view, maximised through a link made from the copied one. These
  // pages ask for WebGL2 at once (`?webgl`): the WebGPU attempt and its
  // reload were checked above and would only cost time here.
  const toml = linkToml(link);
  const gl = `${base}?webgl`;
  for (const view of viewIds()) {
    const p = await open(context, linkOf(gl, withMaximised(toml, view)), `view ${view}`);
    await p.page.waitForTimeout(SETTLE_MS);
    // The view's area: right of the panel, below the menu.
    notBlank(await shot(p.page, `webgpu-view-${view}`), `view ${view}`, [320, 40, W - 10, H - 40]);
    noErrors(p, `view ${view}`);
    await p.page.close();
  }

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
  await a.page.close();
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
