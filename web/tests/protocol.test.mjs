// The page's checks of the GUI protocol (web/public/app/protocol.js over schema.js), without a
// browser: every case of tests/gui/protocol_cases.json, which the C++ checks
// (tests/gui/protocol_test.cc) pass word for word too, so that a message refused on either side
// names the same field.
//
//   node --test --test-reporter=spec web/tests/protocol.test.mjs
import { describe, test } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import {
  checkCommand, checkFrameHeader, checkSceneDocument, checkServerMessage, kProtocol, kVersion,
  table, validate,
} from '../public/app/protocol.js';

const kRepo = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..', '..');
const kCases = JSON.parse(fs.readFileSync(path.join(kRepo, 'tests', 'gui', 'protocol_cases.json'), 'utf8'));

const kChecks = {
  command: (c) => checkCommand(c.message),
  server: (c) => checkServerMessage(c.message, c.command ?? ''),
  frame: (c) => checkFrameHeader(c.message),
  scene: (c) => checkSceneDocument(c.message),
};

describe('the page checks the GUI protocol as the server does', () => {
  test('every shared case gives the C++\'s words', () => {
    assert.ok(kCases.length > 30, `${kCases.length} cases`);
    for (const c of kCases) {
      assert.equal(kChecks[c.check](c), c.error, `${c.check} ${JSON.stringify(c.message)}`);
    }
  });

  test('the table is version 2 of saccade-gui, with both directions', () => {
    assert.equal(kProtocol, 'saccade-gui');
    assert.equal(kVersion, 2);
    const count = (channel) => table.messages.filter((m) => m.channel === channel).length;
    assert.equal(count('command'), 15);
    assert.equal(count('text'), 6);  // hello, state, map, reply, error, event
    assert.equal(count('frame'), 1);
    assert.equal(count('document'), 1);
    assert.equal(validate, checkServerMessage);
  });

  test('every reference names a type of the table', () => {
    const refs = new Set();
    const walk = (v) => {
      if (Array.isArray(v)) v.forEach(walk);
      else if (v && typeof v === 'object') {
        if (typeof v.ref === 'string') refs.add(v.ref);
        Object.values(v).forEach(walk);
      }
    };
    walk(table);
    for (const r of refs) assert.ok(r in table.types, `no type '${r}'`);
  });

  test('a non-finite number is refused', () => {
    const state = kCases.find((c) => c.check === 'server' && c.message.type === 'state' && !c.error).message;
    assert.equal(checkServerMessage({ ...state, time: Infinity }), "state: field 'time' must be a finite number");
  });
});
