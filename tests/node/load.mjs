// A bounded load on `ricochet serve`, loopback only: N clients (default 50) subscribed to
// every channel for S seconds (default 10), and one more publishing R inputs a second
// (default 1000) on /input. Prints, per client, the messages received and the slow-client
// notices; the server prints its frame lateness, drops and CPU when stopped.
// Usage: node tests/node/load.mjs ws://127.0.0.1:PORT [N] [S] [R]

import wsProtocol from "@foxglove/ws-protocol";
import WebSocket from "ws";

const { FoxgloveClient } = wsProtocol;
const [url, n = "50", seconds = "10", rate = "1000"] = process.argv.slice(2);
if (!url.startsWith("ws://127.0.0.1:")) {
  console.error("load: loopback only (ws://127.0.0.1:PORT)");
  process.exit(2);
}
const clients = [];
for (let i = 0; i < Number(n); i++) {
  const c = { received: 0, bytes: 0, notices: 0 };
  const client = new FoxgloveClient({ ws: new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
  client.on("advertise", (list) => list.forEach((ch) => client.subscribe(ch.id)));
  client.on("message", ({ data }) => {
    c.received += 1;
    c.bytes += data.byteLength;
  });
  client.on("status", (s) => {
    if (s.message.includes("too slow")) c.notices += 1;
  });
  c.client = client;
  clients.push(c);
}
const publisher = new FoxgloveClient({ ws: new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
let sent = 0;
let refused = 0;
publisher.on("status", () => (refused += 1));
publisher.on("serverInfo", () => {
  const input = publisher.advertise({ topic: "/input", encoding: "json", schemaName: "ricochet.Input" });
  const perTick = Number(rate) / 100;
  const timer = setInterval(() => {
    for (let k = 0; k < perTick; k++) {
      const turn = sent % 2 === 0 ? 0.5 : -0.5;
      publisher.sendMessage(input, new TextEncoder().encode(JSON.stringify({ action: "turn", body: "ship", input: turn })));
      sent += 1;
    }
  }, 10);
  setTimeout(() => clearInterval(timer), Number(seconds) * 1000);
});
setTimeout(() => {
  const got = clients.map((c) => c.received).sort((a, b) => a - b);
  const mb = clients.reduce((s, c) => s + c.bytes, 0) / 1e6;
  const notices = clients.reduce((s, c) => s + c.notices, 0);
  console.log(
    `load: ${clients.length} clients for ${seconds} s: messages received per client min ${got[0]}, ` +
      `median ${got[Math.floor(got.length / 2)]}, max ${got[got.length - 1]}; ${mb.toFixed(1)} MB in all; ` +
      `${notices} slow-client notices; inputs sent ${sent}, refused ${refused}`,
  );
  clients.forEach((c) => c.client.close());
  publisher.close();
  setTimeout(() => process.exit(0), 200);
}, Number(seconds) * 1000 + 500);
