// A Foxglove WebSocket protocol client built on Foxglove's own npm package
// (@foxglove/ws-protocol, with the npm `ws` WebSocket): connects to a
// sandbox's --foxglove server, subscribes to every channel it advertises and
// prints what happens as JSON lines: {"event":"serverInfo"}, {"event":
// "subscribed","topic","schemaName"}, {"event":"message","topic",
// "schemaName","timestamp","message"} (the JSON payload parsed), and any
// status message the server sends. Ends when the server closes the connection.
//
//   NODE_PATH=build/node/node_modules node foxglove_client.cjs ws://127.0.0.1:PORT/
"use strict";
const { FoxgloveClient } = require("@foxglove/ws-protocol");
const WebSocket = require("ws");

function print(event) {
  process.stdout.write(JSON.stringify(event) + "\n");
}

const client = new FoxgloveClient({
  ws: new WebSocket(process.argv[2], [FoxgloveClient.SUPPORTED_SUBPROTOCOL]),
});
const bySubscription = new Map();
client.on("serverInfo", (info) => print({ event: "serverInfo", name: info.name }));
client.on("advertise", (channels) => {
  for (const channel of channels) {
    bySubscription.set(client.subscribe(channel.id), channel);
    print({ event: "subscribed", topic: channel.topic, schemaName: channel.schemaName,
            encoding: channel.encoding });
  }
});
client.on("message", ({ subscriptionId, timestamp, data }) => {
  const channel = bySubscription.get(subscriptionId);
  const text = new TextDecoder().decode(
      new Uint8Array(data.buffer, data.byteOffset, data.byteLength));
  print({ event: "message", topic: channel.topic, schemaName: channel.schemaName,
          timestamp: timestamp.toString(), message: JSON.parse(text) });
});
client.on("status", (status) => print({ event: "status", level: status.level, message: status.message }));
client.on("error", (error) => {
  process.stderr.write(`foxglove_client: ${error && error.message ? error.message : error}\n`);
  process.exit(1);
});
client.on("close", () => process.exit(0));
