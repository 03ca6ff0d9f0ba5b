// The official Foxglove WebSocket client (@foxglove/ws-protocol's FoxgloveClient, which
// speaks foxglove.websocket.v1, as Lichtblick does) against a running `ricochet serve`.
// Usage: node tests/node/client.mjs ws://127.0.0.1:PORT
// Connects; checks the server info and every advertised channel (protobuf, with a schema);
// subscribes to /stats and /scene and checks that /stats frames arrive in order; publishes
// inputs on /input (two applied, one refused and answered with a status); calls the
// services /pause, /step, /seek (back) and /reset and checks their answers; disconnects.
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
  "/scene", "/scene/static", "/tf", "/scene/contacts", "/bodies", "/contacts", "/stats", "/events", "/input",
];
let info;
let channels = [];
const frames = [];
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
  client.on("message", ({ subscriptionId, data }) => {
    const bytes = new Uint8Array(data.buffer, data.byteOffset, data.byteLength);
    if (subscriptionId === stats) frames.push(statsFrame(bytes));
    if (subscriptionId === scene) scenes += 1;
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
  await callService("/play", {});
  servicesDone = `services: paused at ${paused.frame}, stepped to ${stepped.frame}, sought back to ${back.frame}, reset to ${reset.frame}`;
}
let servicesDone = "";

function finish() {
  for (let i = 1; i < frames.length; i++) {
    if (frames[i] !== frames[i - 1] + 1) fail(`/stats frames out of order: ${frames.slice(0, 20)}`);
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
