// Runs a WebAssembly test binary built for wasm32-wasip1 under Node.js's WASI
// (Cargo's runner for that target in .ci/simd.sh): `node .ci/wasi-run.mjs
// FILE.wasm [ARGS…]`. The exit status is the program's.
import fs from "node:fs";
import process from "node:process";
import { WASI } from "node:wasi";

const [file, ...args] = process.argv.slice(2);
if (!file) {
  console.error("usage: node .ci/wasi-run.mjs FILE.wasm [ARGS...]");
  process.exit(2);
}
const wasi = new WASI({
  version: "preview1",
  args: [file, ...args],
  env: { RUST_BACKTRACE: "0" },
  returnOnExit: true,
});
const module = await WebAssembly.compile(fs.readFileSync(file));
const instance = await WebAssembly.instantiate(module, wasi.getImportObject());
process.exitCode = wasi.start(instance);
