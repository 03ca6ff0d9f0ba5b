// The official Foxglove WebSocket client (@foxglove/ws-protocol's FoxgloveClient, which
// speaks foxglove.websocket.v1, as Lichtblick does) against a running `ricochet serve`.
// Usage: node tests/node/client.mjs ws://127.0.0.1:PORT
// Connects; checks the server info and every advertised channel (protobuf, with a schema);
// subscribes to /stats and /scene and checks that /stats frames arrive in order; publishes
// inputs on /input (two applied, one refused and answered with a status); calls the
// services /pause, /step, /seek (back) and /reset and checks their answers; at frame 0 of
// the reset (the scenario's own positions: the ship at the origin, angle 0, its triangle's
// back edge at x = -0.8), calls /query (a ray, a point, an unknown layer) and publishes a
// /clicked_point as Lichtblick's 3D panel does (JSON geometry_msgs/PointStamped), whose
// answer comes on /events; disconnects.
// Exits 1 with a message on any failure; prints a summary line on success.

import wsProtocol from "@foxglove/ws-protocol";
import WebSocket from "ws";

const { FoxgloveClient } = wsProtocol;

const url = process.argv[2];
const fail = (why) => {
  console.error(`node client: FAILED: ${why}`);
  process.exit(1);
};
setTimeout(() => fail("timed out after 20 s"), 20_000).unref();

const client = new FoxgloveClient({
  ws: new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]),
});
const expected = [
  "/scene", "/scene/static", "/tf", "/scene/contacts", "/bodies", "/contacts", "/stats", "/events", "/input/recorded",
];
let info;
let channels = [];
const frames = [];
// Whether /reset was answered: the session then starts again at frame 0.
let wasReset = false;
let scenes = 0;
const statuses = [];
let published = false;

// The `frame` field (1) of a ricochet.Stats message: a varint after the tag byte 0x08.
function statsFrame(bytes) {
  if (bytes.length === 0) return 0; // frame 0: the default, not encoded
  if (bytes[0] !== 0x08) return 0;
  let value = 0, shift = 0;
  for (let i = 1; i < bytes.length; i++) {
    value += (bytes[i] & 0x7f) * 2 ** shift;
    if ((bytes[i] & 0x80) === 0) break;
    shift += 7;
  }
  return value;
}

// The `message` (3) and `name` (4) strings of a foxglove.Log: the top-level fields read by
// their wire types (varint 0, fixed64 1, length-delimited 2, fixed32 5).
function logLine(bytes) {
  const out = {};
  let i = 0;
  const varint = () => {
    let value = 0, shift = 0;
    for (;;) {
      const b = bytes[i++];
      value += (b & 0x7f) * 2 ** shift;
      if ((b & 0x80) === 0) return value;
      shift += 7;
    }
  };
  while (i < bytes.length) {
    const key = varint();
    const field = Math.floor(key / 8), wire = key % 8;
    if (wire === 0) varint();
    else if (wire === 1) i += 8;
    else if (wire === 5) i += 4;
    else if (wire === 2) {
      const len = varint();
      const text = new TextDecoder().decode(bytes.subarray(i, i + len));
      if (field === 3) out.message = text;
      if (field === 4) out.name = text;
      i += len;
    } else fail(`foxglove.Log: wire type ${wire}`);
  }
  return out;
}
let clicked;

client.on("error", (e) => fail(`client error: ${e}`));
client.on("serverInfo", (i) => {
  info = i;
  if (!i.capabilities.includes("clientPublish")) fail(`capabilities ${i.capabilities}`);
});
client.on("status", (s) => statuses.push(s));
let services = [];
client.on("advertiseServices", (list) => (services = services.concat(list)));
const answers = new Map();
client.on("serviceCallResponse", (r) => {
  const text = new TextDecoder().decode(new Uint8Array(r.data.buffer, r.data.byteOffset, r.data.byteLength));
  answers.get(r.callId)?.resolve(JSON.parse(text));
});
client.on("serviceCallFailure", (f) => answers.get(f.callId)?.reject(new Error(f.message)));
let nextCall = 1;
function callService(name, request) {
  const service = services.find((s) => s.name === name);
  if (!service) fail(`no service ${name}: ${services.map((s) => s.name)}`);
  const callId = nextCall++;
  const answer = new Promise((resolve, reject) => answers.set(callId, { resolve, reject }));
  client.sendServiceCallRequest({
    serviceId: service.id,
    callId,
    encoding: "json",
    data: new TextEncoder().encode(JSON.stringify(request)),
  });
  return answer;
}
client.on("advertise", (list) => {
  channels = channels.concat(list);
  const topics = channels.map((c) => c.topic);
  if (JSON.stringify(topics) !== JSON.stringify(expected)) fail(`channels ${topics}`);
  for (const c of channels) {
    if (c.encoding !== "protobuf" || c.schemaEncoding !== "protobuf" || c.schema.length < 100) {
      fail(`channel ${c.topic}: ${c.encoding} / ${c.schemaEncoding}, schema of ${c.schema.length}`);
    }
  }
  const id = (t) => channels.find((c) => c.topic === t).id;
  const stats = client.subscribe(id("/stats"));
  const scene = client.subscribe(id("/scene"));
  const events = client.subscribe(id("/events"));
  client.on("message", ({ subscriptionId, data }) => {
    const bytes = new Uint8Array(data.buffer, data.byteOffset, data.byteLength);
    if (subscriptionId === stats) frames.push(statsFrame(bytes));
    if (subscriptionId === scene) scenes += 1;
    if (subscriptionId === events) {
      const line = logLine(bytes);
      if (line.name === "click") clicked?.(line.message);
    }
    if (frames.length === 10 && !published) {
      published = true;
      publish();
    }
  });
});

function publish() {
  const input = client.advertise({ topic: "/input", encoding: "json", schemaName: "ricochet.Input" });
  const send = (o) => client.sendMessage(input, new TextEncoder().encode(JSON.stringify(o)));
  send({ action: "thrust", body: "ship", on: true });
  send({ action: "turn", body: "ship", input: -0.5 });
  send({ action: "jump", body: "no such body" });
  setTimeout(() => services_().then(finish, (e) => fail(`services: ${e.message}`)), 1000);
}

async function services_() {
  const paused = await callService("/pause", {});
  if (paused.paused !== true) fail(`/pause answered ${JSON.stringify(paused)}`);
  const stepped = await callService("/step", { frames: 5 });
  if (stepped.frame !== paused.frame + 5) fail(`/step 5 from ${paused.frame} answered ${JSON.stringify(stepped)}`);
  const back = await callService("/seek", { frame: 10 });
  if (back.frame !== 10 || !back.recording) fail(`/seek 10 answered ${JSON.stringify(back)}`);
  const reset = await callService("/reset", {});
  if (reset.frame !== 0) fail(`/reset answered ${JSON.stringify(reset)}`);
  wasReset = true;
  const queried = await queries();
  await callService("/play", {});
  servicesDone = `services: paused at ${paused.frame}, stepped to ${stepped.frame}, sought back to ${back.frame}, reset to ${reset.frame}; ${queried}`;
}
let servicesDone = "";

// At frame 0, still paused: the ship at (0, 0), angle 0.
async function queries() {
  const near = (a, b) => Math.abs(a - b) <= 1e-9;
  const ray = await callService("/query", {
    kind: "ray", origin: [-10, 0], direction: [2, 0], max_distance: 20, layers: ["ship"],
  });
  const hit = ray.hits?.[0];
  const exact = ray.count === 1 && hit.body === "0:0" && hit.name === "ship" && hit.layer === "ship" &&
    near(hit.distance, 9.2) && near(hit.point[0], -0.8) && near(hit.point[1], 0) &&
    near(hit.normal[0], -1) && near(hit.normal[1], 0);
  if (!exact) fail(`/query ray answered ${JSON.stringify(ray)}`);
  const point = await callService("/query", { kind: "point", point: [0.2, 0] });
  if (point.count !== 1 || point.hits[0].name !== "ship") fail(`/query point answered ${JSON.stringify(point)}`);
  const refused = await callService("/query", { kind: "point", point: [0, 0], layers: ["lava"] }).then(
    (a) => fail(`/query with an unknown layer answered ${JSON.stringify(a)}`),
    (e) => e.message,
  );
  if (!refused.includes("no layer")) fail(`/query with an unknown layer: ${refused}`);
  // As Lichtblick's 3D panel: advertised with the first encoding the server supports, the
  // message as its makePointMessage builds it, in the display frame.
  const channel = client.advertise({
    topic: "/clicked_point", encoding: "json", schemaName: "geometry_msgs/PointStamped",
  });
  const answer = new Promise((resolve) => (clicked = resolve));
  const now = Date.now();
  const message = {
    header: { stamp: { sec: Math.floor(now / 1000), nsec: (now % 1000) * 1e6 }, frame_id: "world" },
    point: { x: 0.2, y: 0, z: 0 },
  };
  client.sendMessage(channel, new TextEncoder().encode(JSON.stringify(message)));
  const line = await answer;
  if (!line.startsWith("click at [0.2, 0]: ship #0:0 (layer ship, dynamic, ") || !line.includes("position [0, 0], angle 0,")) {
    fail(`the click was answered ${line}`);
  }
  return `/query: the ship at distance ${hit.distance}, a point, an unknown layer refused; a click answered on /events`;
}

function finish() {
  for (let i = 1; i < frames.length; i++) {
    // After the reset the session starts again at frame 0: its /stats may come in the same
    // write as the answers that follow (the server writes what is queued together), so
    // before this check runs.
    const restart = wasReset && frames[i] === 0;
    if (frames[i] !== frames[i - 1] + 1 && !restart) {
      fail(`/stats frames out of order at ${i}: ${frames.slice(Math.max(0, i - 5), i + 5)}`);
    }
  }
  if (scenes < 1) fail("no /scene message (it is latched: one comes at once)");
  if (!statuses.some((s) => s.level === 2 && s.message.includes("no such body"))) {
    fail(`the refused input was not answered: ${JSON.stringify(statuses)}`);
  }
  console.log(
    `node client: ok: ${info.name}, ${channels.length} channels, ${frames.length} /stats frames ` +
      `(${frames[0]}..${frames[frames.length - 1]}), ${scenes} /scene, 3 inputs sent, 1 refused; ${servicesDone}`,
  );
  client.close();
  process.exit(0);
}
