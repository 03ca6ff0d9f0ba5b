// The browser example (crates/portable/examples/browser_asteroids.rs, wasm32-unknown-unknown)
// loaded as a page would load it: no WASI, no imports, only its exported functions.
//   node scripts/browser-asteroids.mjs browser_asteroids.wasm [ASTEROIDS FRAMES]
// Prints the determinism gate's text for `asteroids-N` (crates/portable/src/lib.rs), which
// must equal the native program's block for the same scene.
import { readFile } from "node:fs/promises";

const [wasmPath, n = "200", frames = "300"] = process.argv.slice(2);
const { instance } = await WebAssembly.instantiate(await readFile(wasmPath), {});
const sim = instance.exports;
// A wasm i64 reaches JavaScript as a signed BigInt: print its 64 bits as the program does.
const hex = (v) => BigInt.asUintN(64, v).toString(16).padStart(16, "0");
const name = `asteroids-${n}`;
const bodies = sim.asteroids_new(Number(n), Number(frames));
if (bodies === 0) {
  console.error(`${name}: the example refused the scene`);
  process.exit(2);
}
const lines = [`scene ${name} frames ${frames} bodies ${bodies}`];
for (let k = 0; k <= Number(frames); k++) {
  const frame = BigInt.asUintN(64, sim.step());
  lines.push(`${frame} ${hex(sim.checksum())} ${hex(sim.digest())}`);
}
lines.push(`end ${name} frames ${frames} bodies ${sim.bodies()} hash ${hex(sim.digest())}`);
console.log(lines.join("\n"));
