// The browser client in a real browser: Debian's Chromium, headless, driven by
// playwright-core (never a browser of Playwright's own).
//
// Usage: node test.mjs [SERVER [RICOCHET]]
//   SERVER: the Coin Rush server binary (default: ../../../target/debug/ricochet-coin-rush,
//   or $CARGO_TARGET_DIR's); RICOCHET: the ricochet binary, to read the room's recording
//   (default: the same folder's `ricochet`).
//
// Builds the page's bundle (esbuild); starts the server on a free loopback port, recording
// its rooms; page A joins room `test` as ada (player 1: the first spawn point, x = -4) and
// page B as bob; A holds the left arrow: its runner runs 6 units/s left to the floor coin
// at x = -8 (its left face meets the coin's edge at x = -7.65, past 3.25 units), so ada
// scores 1; B sees A's body move left by more than 3 units; both pages show ada 1, bob 0;
// screenshots of both are saved (screenshots/) and each has drawn bodies (pixels that are
// not the background) inside the canvas. Then the pages close (the players leave), the
// server stops, and the room's recording holds, at the frame page B last showed, the same
// scores page B showed. Everything within 60 s, on 127.0.0.1.

import { spawn, execFileSync } from "node:child_process";
import { mkdirSync, mkdtempSync, readdirSync, rmSync } from "node:fs";
import { tmpdir } from "node:os";
import { dirname, join } from "node:path";
import { fileURLToPath, pathToFileURL } from "node:url";

import { chromium } from "playwright-core";

const here = dirname(fileURLToPath(import.meta.url));
const target = process.env.CARGO_TARGET_DIR ?? join(here, "../../../target");
const serverBin = process.argv[2] ?? join(target, "debug/ricochet-coin-rush");
const ricochetBin = process.argv[3] ?? join(dirname(serverBin), "ricochet");
const ROOM = "test";
// The background the page clears the canvas to (#10131a).
const BACKGROUND = [0x10, 0x13, 0x1a];

let server = null;
let browser = null;
const work = mkdtempSync(join(tmpdir(), "coin-rush-web-"));

async function cleanup() {
  if (browser) await browser.close().catch(() => {});
  if (server && server.exitCode === null) server.kill("SIGKILL");
  rmSync(work, { recursive: true, force: true });
}

async function fail(why) {
  console.error(`coin-rush web: FAILED: ${why}`);
  await cleanup();
  process.exit(1);
}

setTimeout(() => fail("timed out after 60 s"), 60_000).unref();

// Waits until `check()` is truthy (polling every 50 ms), else fails with `what`.
async function until(what, check, ms = 15_000) {
  const end = Date.now() + ms;
  for (;;) {
    const value = await check();
    if (value) return value;
    if (Date.now() > end) await fail(`${what}: not within ${ms / 1000} s`);
    await new Promise((r) => setTimeout(r, 50));
  }
}

// The bundle, built now: what the page loads is this source.
execFileSync(join(here, "node_modules/.bin/esbuild"), [
  join(here, "src/client.js"), "--bundle", "--format=iife", "--target=es2020",
  `--outfile=${join(here, "dist/client.js")}`, "--log-level=warning",
], { stdio: "inherit" });

// The server, on a free port, recording each room into `work/rooms`.
const records = join(work, "rooms");
mkdirSync(records);
server = spawn(serverBin, ["--bind", "127.0.0.1:0", "--record", records], {
  stdio: ["ignore", "ignore", "pipe"],
});
let serverErr = "";
server.stderr.on("data", (d) => (serverErr += d));
server.on("error", (e) => fail(`cannot start ${serverBin}: ${e.message}`));
const base = await until("the server's address on its stderr", () =>
  serverErr.match(/ws:\/\/127\.0\.0\.1:\d+/)?.[0],
);
const roomUrl = `${base}/rooms/${ROOM}`;

browser = await chromium.launch({
  executablePath: "/usr/bin/chromium",
  headless: true,
  args: [
    "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
  ],
});

const pageUrl = (name) => {
  const u = pathToFileURL(join(here, "index.html"));
  u.search = new URLSearchParams({ url: roomUrl, name }).toString();
  return u.href;
};

async function open(name) {
  const page = await browser.newPage({ viewport: { width: 900, height: 420 } });
  page.on("pageerror", (e) => fail(`page ${name}: ${e.message}`));
  await page.goto(pageUrl(name));
  const player = await until(`${name} joined`, () =>
    page.evaluate(() => window.coinRush.player ?? window.coinRush.error),
  );
  if (typeof player !== "number") await fail(`${name} could not join: ${player}`);
  return { page, player };
}

// A joins first (player 1, spawn x = -4), then B.
const a = await open("ada");
const b = await open("bob");
if (a.player !== 1 || b.player !== 2) await fail(`players ${a.player} and ${b.player}, expected 1 and 2`);

// Ada's runner as page B draws it.
const adaOnB = () =>
  b.page.evaluate(() => {
    const p = window.coinRush.state?.players.find((q) => q.name === "ada");
    return p ? window.coinRush.bodyPosition(p.body) : null;
  });
const start = await until("page B draws ada's runner", adaOnB);
if (Math.abs(start.x - -4) > 0.5) await fail(`ada starts at x = ${start.x} on page B, expected -4`);

await a.page.bringToFront();
await a.page.keyboard.down("ArrowLeft");
const moved = await until("page B sees ada's runner move left 3 units", async () => {
  const p = await adaOnB();
  return p && p.x < start.x - 3 ? p : null;
});
await new Promise((r) => setTimeout(r, 500));
await a.page.keyboard.up("ArrowLeft");

// Both pages show ada's point from the coin at x = -8.
const shown = (page) =>
  page.evaluate(() =>
    [...document.querySelectorAll("#scores tr")].map((r) => [
      r.dataset.name,
      Number(r.children[1].textContent),
    ]),
  );
for (const [who, p] of [["A", a.page], ["B", b.page]]) {
  await until(`page ${who} shows ada 1, bob 0`, async () => {
    const rows = Object.fromEntries(await shown(p));
    return rows.ada === 1 && rows.bob === 0;
  });
}
const lastOnB = await b.page.evaluate(() => window.coinRush.state);

// Screenshots: bodies drawn inside the canvas (counted in the PNG itself, decoded by the
// browser).
mkdirSync(join(here, "screenshots"), { recursive: true });
for (const [who, p] of [["a", a.page], ["b", b.page]]) {
  const file = join(here, "screenshots", `page-${who}.png`);
  const png = await p.screenshot({ path: file });
  const box = await p.locator("#room").boundingBox();
  const drawn = await p.evaluate(
    async ({ b64, box, bg }) => {
      const blob = await (await fetch(`data:image/png;base64,${b64}`)).blob();
      const img = await createImageBitmap(blob);
      const c = new OffscreenCanvas(img.width, img.height);
      const g = c.getContext("2d");
      g.drawImage(img, 0, 0);
      const d = g.getImageData(Math.ceil(box.x) + 1, Math.ceil(box.y) + 1,
        Math.floor(box.width) - 2, Math.floor(box.height) - 2).data;
      let n = 0;
      for (let i = 0; i < d.length; i += 4) {
        if (Math.abs(d[i] - bg[0]) + Math.abs(d[i + 1] - bg[1]) + Math.abs(d[i + 2] - bg[2]) > 24) n++;
      }
      return { n, total: d.length / 4 };
    },
    { b64: png.toString("base64"), box, bg: BACKGROUND },
  );
  // 62 tiles of 24 × 24 pixels alone cover over 30,000 pixels.
  if (drawn.n < 10_000) await fail(`page ${who}'s screenshot: ${drawn.n} drawn pixels of ${drawn.total}`);
  console.log(`page ${who}: ${drawn.n} of ${drawn.total} canvas pixels drawn (${file})`);
}

// The players leave; the server stops and finishes the room's recording.
await a.page.close();
await b.page.close();
await browser.close();
browser = null;
server.kill("SIGTERM");
await until("the server stopped", () => server.exitCode !== null, 10_000);
if (server.exitCode !== 0) await fail(`the server exited ${server.exitCode}: ${serverErr}`);
const logs = readdirSync(records).filter((f) => f.endsWith(".mcap"));
if (logs.length !== 1) await fail(`expected one room recording, found ${logs}`);
const dump = execFileSync(ricochetBin, ["dump", join(records, logs[0]), "--topic", "/game"], {
  encoding: "utf8",
  maxBuffer: 64 << 20,
});
const recorded = dump
  .split("\n")
  .filter((l) => l.trim())
  .map((l) => JSON.parse(l))
  .map((m) => m.data ?? m);
const same = recorded.find((s) => s.frame === lastOnB.frame);
if (!same) await fail(`the recording has no /game state of frame ${lastOnB.frame}`);
const scoresOf = (s) => JSON.stringify(s.players.map((p) => [p.name, p.score]));
if (scoresOf(same) !== scoresOf(lastOnB)) {
  await fail(`frame ${lastOnB.frame}: page B showed ${scoresOf(lastOnB)}, recorded ${scoresOf(same)}`);
}
console.log(
  `ada moved from x = ${start.x.toFixed(2)} to ${moved.x.toFixed(2)} on page B; frame ` +
    `${lastOnB.frame}: page B and the recording agree on ${scoresOf(same)}`,
);
await cleanup();
console.log("coin-rush web: 1 passed, 0 failed");
process.exit(0);
