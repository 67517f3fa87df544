#pragma once
// The hand-written sections of docs/gui-protocol.md, between which protocol_docs.cc writes the
// protocol table's messages; and the hand-written parts of web/public/app/protocol.js.

namespace saccade::gui::protocol {

inline constexpr const char* kIntroProse =
    R"md(`saccade demo --gui` and `saccade gui --scene FILE` serve the browser GUI and speak this
protocol. It is also the remote-control interface for scripts: anything that speaks HTTP and
WebSocket can watch the head and command it. The server is `include/saccade/server/gui_server.h`.
A change that breaks a client raises the version.

This page is generated from the protocol's table (`src/gui/protocol_table.cc`), from which
the server checks every command and every message it writes, and the page
(`web/public/app/protocol.js`, generated from the same table) checks every message it
receives, by

    saccade gui --protocol-markdown > docs/gui-protocol.md
    saccade gui --protocol-js > web/public/app/protocol.js

and the tests `docs.gui_protocol` and `docs.gui_protocol_js` fail when either and the code
differ. Its prose lives in `src/gui/internal_protocol_prose.h`.

Units are SI and radians. A pose is its 4x4 matrix, row by row:
`[[r00, r01, r02, x], [r10, r11, r12, y], [r20, r21, r22, z], [0, 0, 0, 1]]` (`X_WC` is the
camera C in the world W, DESIGN.md), the type `pose` below. It is saccade's one JSON form of a pose
(`include/saccade/geometry/json.h`), the same as in `saccade render`'s `frames.jsonl`
([cli](cli.md)) and in the messages; its numbers are doubles written to read back exactly.
Version 1 sent each pose as one flat list of 16 numbers, row-major; version 2 sends the four
rows (a client of version 1 reads `m[4 * r + c]`, one of version 2 `m[r][c]`). Camera frames
are OpenCV's (x right, y down, z forward); the world is z up.

## Access and security

**The threat.** The GUI drives the head, and with a hardware file the head is the real robot's
servos. Its server listens on the operator's machine, where the operator also browses the web.
Three kinds of stranger could reach it:
- a **web page of another origin** that the operator visits: a browser lets any page open a
  WebSocket to `ws://127.0.0.1:PORT/` (WebSockets have no same-origin policy), so without a
  check that page could send `{"type": "joints", ...}` and move the head;
- a **DNS-rebinding page**: a name of the attacker's (`evil.example.com`) that first resolves to
  the attacker's server and then to 127.0.0.1, so that the page reads and commands the GUI as
  if it were its own origin;
- **another user or program** on the machine (or on the network, when listening beyond
  loopback) that finds the port.

**What the server checks**, in this order, on every request:
1. **Host.** The `Host` header must name this server: `localhost`, a loopback address
   (127.0.0.0/8, `[::1]`), the `--listen` address (any IP address when listening on `0.0.0.0`
   or `::`), or a name given with `--allow-host NAME` (repeatable; e.g. the head computer's
   `robot-head.local`). A rebinding page sends its own name: **403**, and a log line naming the
   peer and the Host.
2. **Origin.** A request that carries an `Origin` header (browsers send one on every WebSocket
   and on every cross-origin request) must come from the server's own page: `Origin` equal to
   `http://` + its `Host`. Another page's origin, `null` included: **403**, and a log line.
   Programs that send no `Origin` (scripts such as `bench/gui_stream.py`) pass this check and
   meet the token.
3. **Token.** The WebSocket and every `/api/` request must present the access token:
   `?token=TOKEN` in the URL or the header `Authorization: Bearer TOKEN`. Without it: **401**,
   nothing else. The token is
   - on loopback: a **random token per run** (128 bits from the kernel), printed in the address
     at start, as Jupyter does: `gui: serving http://127.0.0.1:8080/?token=3f9c...`; open that
     address. `--token TOKEN` (or `SACCADE_GUI_TOKEN`) sets one of your own, e.g. to keep a
     bookmarked address across restarts; `--no-token` serves without one (then any local
     program may drive the head; pages of other origins still may not);
   - beyond loopback (`--listen 0.0.0.0`, a LAN address): **required**, given with `--token`
     or `SACCADE_GUI_TOKEN`; saccade refuses to start without one, and refuses `--no-token`.
   Tokens are compared in constant time.

Static files (the page, three.js) need no token: they hold no state; they still need an allowed
Host. A page that was opened with the token keeps it in its address and sends it on the
WebSocket and every `/api/` request.

)md";

inline constexpr const char* kHttpProse = R"md(## HTTP
| path | what |
|---|---|
| `/` | the page (`web/public/index.html`) |
| `/app/...` | the page's own scripts and styles (`web/public/app/`) |
| `/vendor/three/...` | three.js from `web/node_modules/three/` (npm, pinned by `web/package-lock.json`) |
| `/api/scene` | the scene as JSON (below); needs the token |
| `/api/models/N.bin` | model N's triangle meshes, binary (below); needs the token |
| `/api/textures/N.png` | texture N as PNG; needs the token |
| `/api/status` | server status: clients and what each was sent, skipped and acknowledged (`frame_window`, below); needs the token |

The page draws exactly what the renderer draws: the meshes and textures the scene loader
read (Assimp: OBJ, glTF 2.0, Collada, PLY, STL, ...; the primitives; the pictures; the
robot's body), not a second parse of the model files by other loaders.

)md";

inline constexpr const char* kModelsProse = R"md(### `/api/models/N.bin`
Little-endian, the meshes one after another in the order of `meshes`; for each mesh of V
vertices and I indices: V x 3 float32 positions, V x 3 float32 normals, V x 2 float32 uvs
(only when `uvs` is true), I uint32 indices (three per triangle).

)md";

inline constexpr const char* kWebSocketProse = R"md(## WebSocket `/ws`
Text messages are JSON objects with a `type`. On connecting, the server sends `hello`, then the
latest `state` (and the newest `map`, when the pipeline has one).

Every message each way is declared below, field by field. A message breaks the protocol when a
field is missing or of another kind (null only where it says so), a number is not finite or
lies outside its range, a string is not one of its values, an array has the wrong length, or
an object carries a field it does not declare (`head_status` excepted). The server refuses
such a command with an `error` naming the message and the field (`step: field 'count' must be
in [1, 1000], got 5000`), and the page refuses such a message with the same words, in its log.

)md";

inline constexpr const char* kFrameProse = R"md(### Camera frames
Camera frames come as binary messages: a 4-byte little-endian length N, N bytes of a JSON
header, then a JPEG image.

)md";

inline constexpr const char* kCommandsProse = R"md(### Client to server: commands
Every command is a JSON object with `type` and an integer `id` that grows with each
command of the connection (a repeated or smaller id is an error: out of order), and the
fields of its type, no others. Messages over 64 KiB, malformed JSON (or JSON nested deeper
than 64 levels), binary messages, unknown types and commands that break the protocol get an
`error` reply; the simulation and the other clients go on. A message over 1 MiB (16 times the
limit) closes the connection with code 1009 (message too big).

A reply comes as soon as the command is checked; the simulation applies it between two steps,
or within a step while the loop waits for its camera frames (the renderer draws on a thread of
its own), and then sends a `state` that shows it at once: the new `targets` within a few
milliseconds, the joints moving at the end of that step or the next.

)md";

inline constexpr const char* kFlowProse = R"md(### Flow control of camera frames
The server writes one message at a time to each client and keeps only the newest frame of
each camera waiting, so a client that reads slowly misses frames but never holds the server.
What it cannot see is how much lies in the socket buffers and in the client itself: a client
that reads frames off the socket faster than it can draw them (a browser on a busy machine, a
script that works on each image, a slow network) lets frames pile up there, and every state
and reply behind them arrives late. With `bench/gui_stream.py --frame-ms 150` (a client that
takes 150 ms per frame, against 20 frames/s per camera) a `ping` took 11 s to come back.

A client bounds this by asking for a window:
`{"type": "frame_window", "id": 1, "frames": 4}`. From then on the server sends a frame only
while fewer than 4 frames it sent are unacknowledged; frames that wait are replaced by newer
ones of the same camera (the client gets the newest when it has room). The client
acknowledges with `{"type": "frame_ack", "id": 9, "frames": N}`, where N counts every frame it
has finished with since it connected (shown, dropped, or not wanted: a world camera's). N
never decreases and never exceeds the frames sent; either is an error that changes nothing.
States, replies and events are not counted and never wait for acknowledgements. The same
client with a window of 4 got its `ping` back in 611 ms (4 frames x 150 ms), with 1 in 152 ms;
a client that keeps up loses nothing by asking (21.5 and 19.5 steps/s to the client, one run
each, within the run-to-run spread). The page asks for a window of 4 (`?frame_window=N` in its address sets
another) and acknowledges each frame when it has decoded and drawn it, failed to decode it, or replaced it
before showing it (docs/gui.md has what that does for a slow page).
`/api/status` shows each client's `frame_window` and `frames_acked` beside `frames_sent`.
Without `frame_window` (the default, and what a client of version 1 before it gets) frames go
as fast as the connection takes them.
)md";

inline constexpr const char* kJsHeader =
    R"js(// The GUI protocol (docs/gui-protocol.md), generated from its table in the C++
// (src/gui/protocol_table.cc) by
//   saccade gui --protocol-js > web/public/app/protocol.js
// Do not edit: the test docs.gui_protocol_js fails when this file and the table differ. The
// checks are web/public/app/schema.js's, in the same words as the server's.
import { makeChecks } from './schema.js';

)js";

inline constexpr const char* kJsFooter = R"js(export const kProtocol = table.protocol;
export const kVersion = table.version;

/**
 * The first problem of a message, '' when there is none; each names the message and the field
 * ("state: field 'joints.positions.pan' must be a number, got string").
 * checkServerMessage(message, command): a WebSocket text message of the server; a reply is
 * checked against the reply of `command` (the type of the command it answers) when given.
 * checkFrameHeader(header), checkSceneDocument(scene), checkCommand(command).
 */
export const { checkServerMessage, checkFrameHeader, checkSceneDocument, checkCommand } =
  makeChecks(table);

/** A server's text message: checkServerMessage. */
export const validate = checkServerMessage;
)js";

}  // namespace saccade::gui::protocol
