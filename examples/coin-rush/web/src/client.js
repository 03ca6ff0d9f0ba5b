// Coin Rush in a browser: joins a room of the Coin Rush server as a player, draws the room
// from /scene and /scene/static (foxglove.SceneUpdate, protobuf, decoded with the schema the
// server advertises), sends the keyboard as inputs on /input (JSON), and shows the scores
// from /game (JSON). Everything goes over the Foxglove WebSocket protocol with its official
// client (@foxglove/ws-protocol); protobufjs decodes the scenes.
//
// The page's URL says where and who: index.html?url=ws://127.0.0.1:8766/rooms/lobby&name=ada
// Keys: left and right arrows run, space jumps, Z zaps the way the runner last ran.
//
// What the page knows is on `window.coinRush` (for tests and the curious): the player's
// number, the last /game state, and each drawn entity by id.

import { FoxgloveClient } from "@foxglove/ws-protocol";
import protobuf from "protobufjs";
import descriptor from "protobufjs/ext/descriptor/index.js";

const params = new URLSearchParams(window.location.search);
const url = params.get("url") ?? "ws://127.0.0.1:8766/rooms/lobby";
const name = params.get("name") ?? "player";

// The arena (examples/coin-rush/src/arena.rs): walls at x = -17 and 16, floor at y = 0,
// 10 tiles high. The view shows it whole with half a tile around.
const VIEW = { left: -18, right: 17, bottom: -1, top: 11 };
const BACKGROUND = "#10131a";

const canvas = document.getElementById("room");
const ctx = canvas.getContext("2d");
const statusLine = document.getElementById("status");
const scores = document.getElementById("scores");

const page = {
  url,
  name,
  player: null,
  error: null,
  state: null,
  // Topic -> (entity id -> entity): each SceneUpdate of a topic is its whole set.
  scenes: new Map(),
  // Every input sent, in order (what the tests look at).
  sent: [],
  // The position of the entity `body/ID` (the first primitive's), or null.
  bodyPosition(body) {
    for (const entities of this.scenes.values()) {
      const e = entities.get(`body/${body}`);
      if (e) {
        const p = (e.cubes[0] ?? e.cylinders[0])?.pose?.position;
        if (p) return { x: p.x, y: p.y };
      }
    }
    return null;
  },
};
window.coinRush = page;

function status(text) {
  statusLine.textContent = text;
}

const client = new FoxgloveClient({
  ws: new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]),
});

// Subscription id -> how its messages are read.
const readers = new Map();
let joinService = null;
let inputChannel = null;
const encoder = new TextEncoder();
const decoder = new TextDecoder();

client.on("open", () => status(`connected to ${url}`));
client.on("close", () => status(page.error ?? "disconnected"));
client.on("error", () => {
  page.error = `cannot connect to ${url}`;
  status(page.error);
});

client.on("advertise", (channels) => {
  for (const ch of channels) {
    if (ch.topic === "/scene" || ch.topic === "/scene/static") {
      if (ch.encoding !== "protobuf" || ch.schemaEncoding !== "protobuf") continue;
      const type = protobufType(ch.schema, ch.schemaName);
      const id = client.subscribe(ch.id);
      readers.set(id, (data) => scene(ch.topic, type, data));
    } else if (ch.topic === "/game" && ch.encoding === "json") {
      const id = client.subscribe(ch.id);
      readers.set(id, (data) => game(JSON.parse(decoder.decode(data))));
    }
  }
});

client.on("advertiseServices", (services) => {
  const join = services.find((s) => s.name === "/join");
  if (join && joinService === null) {
    joinService = join;
    client.sendServiceCallRequest({
      serviceId: join.id,
      callId: 1,
      encoding: "json",
      data: encoder.encode(JSON.stringify({ name })),
    });
  }
});

client.on("serviceCallResponse", (response) => {
  if (joinService === null || response.serviceId !== joinService.id) return;
  const answer = JSON.parse(decoder.decode(response.data));
  page.player = answer.player;
  inputChannel = client.advertise({
    topic: "/input",
    encoding: "json",
    schemaName: "coin-rush.Input",
  });
  status(`playing in ${url} as ${name} (player ${page.player})`);
});

client.on("serviceCallFailure", (failure) => {
  // A refused join (the room is full, a bad name): the server says why.
  if (joinService !== null && failure.serviceId === joinService.id) {
    page.error = `cannot join: ${failure.message}`;
    status(page.error);
  }
});

client.on("status", (s) => {
  // A refused join or input: the server says why.
  if (s.level >= 1) {
    page.error = s.message;
    status(s.message);
  }
});

client.on("message", ({ subscriptionId, data }) => {
  const read = readers.get(subscriptionId);
  if (read) read(new Uint8Array(data.buffer, data.byteOffset, data.byteLength));
});

// The message type named `schemaName` from a base64 FileDescriptorSet.
function protobufType(schema, schemaName) {
  const bytes = Uint8Array.from(atob(schema), (c) => c.charCodeAt(0));
  const set = descriptor.FileDescriptorSet.decode(bytes);
  return protobuf.Root.fromDescriptor(set).lookupType(schemaName);
}

function scene(topic, type, data) {
  const update = type.toObject(type.decode(data), {
    longs: Number,
    defaults: true,
    arrays: true,
  });
  let entities = page.scenes.get(topic);
  if (!entities) {
    entities = new Map();
    page.scenes.set(topic, entities);
  }
  for (const d of update.deletions) {
    // type 1: ALL; 0: MATCHING_ID.
    if (d.type === 1) entities.clear();
    else entities.delete(d.id);
  }
  for (const e of update.entities) entities.set(e.id, e);
  draw();
}

function game(state) {
  page.state = state;
  scores.replaceChildren(
    ...state.players.map((p) => {
      const row = document.createElement("tr");
      row.dataset.name = p.name;
      for (const text of [p.name, String(p.score), p.stunned ? "stunned" : ""]) {
        const cell = document.createElement("td");
        cell.textContent = text;
        row.append(cell);
      }
      if (p.player === page.player) row.className = "me";
      return row;
    }),
  );
  const left = Math.ceil(state.frames_left / 60);
  document.getElementById("clock").textContent = `round ${state.round}, ${left} s left`;
}

// World units to canvas pixels: y up, the whole arena in view.
function transform() {
  const sx = canvas.width / (VIEW.right - VIEW.left);
  const sy = canvas.height / (VIEW.top - VIEW.bottom);
  const s = Math.min(sx, sy);
  return {
    s,
    x: (x) => (x - VIEW.left) * s,
    y: (y) => canvas.height - (y - VIEW.bottom) * s,
  };
}

function colour(c) {
  if (!c) return "#888";
  const to = (v) => Math.round(Math.min(1, Math.max(0, v)) * 255);
  return `rgba(${to(c.r)}, ${to(c.g)}, ${to(c.b)}, ${c.a || 1})`;
}

// The angle about z of a quaternion (x = y = 0 for 2D bodies).
function angle(q) {
  return q ? 2 * Math.atan2(q.z ?? 0, q.w ?? 1) : 0;
}

function draw() {
  const t = transform();
  ctx.fillStyle = BACKGROUND;
  ctx.fillRect(0, 0, canvas.width, canvas.height);
  const mine = page.state?.players.find((p) => p.player === page.player)?.body;
  const names = new Map((page.state?.players ?? []).map((p) => [`body/${p.body}`, p]));
  for (const entities of page.scenes.values()) {
    for (const e of entities.values()) {
      for (const c of e.cubes) {
        const p = c.pose.position;
        ctx.save();
        ctx.translate(t.x(p.x), t.y(p.y));
        ctx.rotate(-angle(c.pose.orientation));
        ctx.fillStyle = colour(c.color);
        ctx.fillRect((-c.size.x / 2) * t.s, (-c.size.y / 2) * t.s, c.size.x * t.s, c.size.y * t.s);
        if (e.id === `body/${mine}`) {
          ctx.strokeStyle = "#fff";
          ctx.lineWidth = 2;
          ctx.strokeRect((-c.size.x / 2) * t.s, (-c.size.y / 2) * t.s, c.size.x * t.s, c.size.y * t.s);
        }
        ctx.restore();
      }
      for (const c of e.cylinders) {
        const p = c.pose.position;
        ctx.beginPath();
        ctx.arc(t.x(p.x), t.y(p.y), (c.size.x / 2) * t.s, 0, 2 * Math.PI);
        ctx.fillStyle = colour(c.color);
        ctx.fill();
      }
      const who = names.get(e.id);
      const at = e.cubes[0]?.pose.position;
      if (who && at) {
        ctx.fillStyle = who.stunned ? "#ff0" : "#fff";
        ctx.font = "12px sans-serif";
        ctx.textAlign = "center";
        ctx.fillText(who.name, t.x(at.x), t.y(at.y + 0.9));
      }
    }
  }
}

// The keyboard: the run input is sent when it changes, a jump or zap when pressed.
const held = new Set();
let run = 0;
let facing = 1;

function send(input) {
  if (inputChannel === null) return;
  page.sent.push(input);
  client.sendMessage(inputChannel, encoder.encode(JSON.stringify(input)));
}

function keys(event, down) {
  if (!["ArrowLeft", "ArrowRight", "Space", "KeyZ"].includes(event.code)) return;
  event.preventDefault();
  if (down && event.repeat) return;
  if (event.code === "ArrowLeft" || event.code === "ArrowRight") {
    if (down) held.add(event.code);
    else held.delete(event.code);
    const want = (held.has("ArrowRight") ? 1 : 0) - (held.has("ArrowLeft") ? 1 : 0);
    if (want !== 0) facing = want;
    if (want !== run) {
      run = want;
      send({ run });
    }
  } else if (down && event.code === "Space") {
    send({ jump: true });
  } else if (down && event.code === "KeyZ" && page.state) {
    // The frame on screen is the one the player aims at: the server checks the zap
    // against the world as it was then.
    send({ zap: { dir: [facing, 0], seen: page.state.frame } });
  }
}

window.addEventListener("keydown", (e) => keys(e, true));
window.addEventListener("keyup", (e) => keys(e, false));
draw();
