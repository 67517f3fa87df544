// The connection to the saccade server (docs/gui-protocol.md, saccade-gui/2): the access
// token, the /api/ documents, and the WebSocket that carries states, camera frames and
// commands. Every message received is checked against the protocol's table (protocol.js): one
// that breaks it is refused, reported with the field named (onProtocolError), and goes no
// further.
import { checkFrameHeader, checkServerMessage } from './protocol.js';

/** The access token from the page's address (?token=...), or '' when there is none. */
export const token = new URLSearchParams(location.search).get('token') || '';

/** Thrown when the server answers 401: the page was opened without the right token. */
export class AccessError extends Error {}

/** `path` with the token appended (every /api/ request and the WebSocket need it). */
export function withToken(path) {
  if (!token) return path;
  return path + (path.includes('?') ? '&' : '?') + 'token=' + encodeURIComponent(token);
}

/** Fetches an /api/ path; throws AccessError on 401 and Error on any other failure. */
export async function fetchApi(path) {
  const response = await fetch(withToken(path));
  if (response.status === 401) throw new AccessError(`${path}: 401 (access token required)`);
  if (!response.ok) throw new Error(`${path}: HTTP ${response.status}`);
  return response;
}

/**
 * The WebSocket session. Callbacks: onHello(msg), onState(state), onFrame(header, jpegBlob),
 * onReply(msg), onError(msg), onEvent(msg), onClose(), and onProtocolError(problem, message,
 * kind) for a message that breaks the protocol (kind 'text' or 'frame'): refused, it reaches
 * no other callback (a refused reply or error resolves its command as an error). Commands get
 * increasing ids.
 */
export class Connection {
  constructor(handlers) {
    this.handlers = handlers;
    this.nextId = 1;
    this.pending = new Map();  // id -> {resolve, sent, type}
    this.checked = 0;  // messages checked against the protocol (text and frame headers)
    const scheme = location.protocol === 'https:' ? 'wss:' : 'ws:';
    this.url = withToken(`${scheme}//${location.host}/ws`);
    this.socket = new WebSocket(this.url);
    this.socket.binaryType = 'arraybuffer';
    this.socket.onmessage = (event) => this.receive(event.data);
    this.socket.onclose = () => {
      // Commands still waiting for a reply never get one: they fail.
      for (const [id, waiting] of this.pending) {
        waiting.resolve({ type: 'error', id, error: 'the connection closed before the reply' });
      }
      this.pending.clear();
      handlers.onClose?.();
    };
  }

  get open() { return this.socket.readyState === WebSocket.OPEN; }

  /** Sends {type, id, ...fields}; resolves with the reply or error message. */
  send(type, fields = {}) {
    const id = this.nextId++;
    const message = { type, id, ...fields };
    return new Promise((resolve) => {
      if (!this.open) { resolve({ type: 'error', id, error: `${type}: not connected` }); return; }
      this.pending.set(id, { resolve, sent: performance.now(), type });
      this.socket.send(JSON.stringify(message));
    });
  }

  receive(data) {
    if (data instanceof ArrayBuffer) { this.receiveFrame(data); return; }
    let message;
    try { message = JSON.parse(data); } catch { return; }
    const h = this.handlers;
    this.checked++;
    const problem = checkServerMessage(message, this.pending.get(message?.id)?.type ?? '');
    if (problem) {
      const answers = message?.type === 'reply' || message?.type === 'error';
      const waiting = answers ? this.pending.get(message.id) : undefined;
      if (waiting) {
        this.pending.delete(message.id);
        waiting.resolve({ type: 'error', id: message.id, error: `refused by the page: ${problem}` });
      }
      h.onProtocolError?.(problem, message, 'text');
      return;
    }
    switch (message.type) {
      case 'hello': h.onHello?.(message); break;
      case 'state': h.onState?.(message); break;
      case 'map': h.onMap?.(message); break;
      case 'event': h.onEvent?.(message); break;
      case 'reply':
      case 'error': {
        const waiting = this.pending.get(message.id);
        if (waiting) { this.pending.delete(message.id); waiting.resolve(message); }
        if (message.type === 'error') h.onError?.(message); else h.onReply?.(message);
        break;
      }
    }
  }

  // Binary frame: 4-byte little-endian header length N, N bytes of JSON header, the JPEG.
  receiveFrame(buffer) {
    if (buffer.byteLength < 4) return;
    const n = new DataView(buffer).getUint32(0, true);
    if (4 + n > buffer.byteLength) return;
    let header;
    try { header = JSON.parse(new TextDecoder().decode(new Uint8Array(buffer, 4, n))); } catch { return; }
    this.checked++;
    const problem = checkFrameHeader(header);
    if (problem) { this.handlers.onProtocolError?.(problem, header, 'frame'); return; }
    const jpeg = new Blob([new Uint8Array(buffer, 4 + n)], { type: 'image/jpeg' });
    this.handlers.onFrame?.(header, jpeg);
  }
}
