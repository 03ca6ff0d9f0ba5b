// Runs a wasm32-wasip1 program under Node's WASI, as the determinism gate does:
//   node scripts/wasi-run.mjs PROGRAM.wasm DIR [ARGS...]
// DIR is visible to the program as /repo (the only directory it may read or write); its
// stdout and stderr are Node's; the exit code is the program's.
import { readFile } from "node:fs/promises";
import { WASI } from "node:wasi";

const [wasmPath, dir, ...args] = process.argv.slice(2);
if (!wasmPath || !dir) {
  console.error("usage: node scripts/wasi-run.mjs PROGRAM.wasm DIR [ARGS...]");
  process.exit(2);
}
const wasi = new WASI({
  version: "preview1",
  args: [wasmPath, ...args],
  env: {},
  preopens: { "/repo": dir },
  returnOnExit: true,
});
const module = await WebAssembly.compile(await readFile(wasmPath));
const instance = await WebAssembly.instantiate(module, wasi.getImportObject());
process.exitCode = wasi.start(instance);
