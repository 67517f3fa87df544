// The GUI protocol's checks over its table (protocol.js, generated from the C++'s): the rules
// and the words of src/gui/protocol.cc, so that a message refused on either side names the same
// field (tests/gui/protocol_cases.json holds both to it). A value must be of its schema's kind
// (null only where the schema says so); numbers are finite and within their range; strings one
// of their values, when listed; arrays of their length; objects carry every required field
// and, unless open, no other. The first problem found is reported: fields in their declared
// order, then unknown fields in name order.

const kKindText = {
  any: 'anything', boolean: 'a boolean', integer: 'an integer', number: 'a number',
  string: 'a string', array: 'an array', object: 'an object',
};

/** 'null', 'boolean', 'number', 'string', 'array' or 'object', as the C++ (nlohmann) names it. */
export function typeName(value) {
  if (value === null) return 'null';
  if (Array.isArray(value)) return 'array';
  return typeof value;
}

const where = (path) => (path === '' ? 'the message' : `field '${path}'`);
const child = (path, name) => (path === '' ? name : `${path}.${name}`);
const isObject = (value) => typeName(value) === 'object';
// Code-unit order: the C++'s std::map order for ASCII names.
const byName = (a, b) => (a < b ? -1 : a > b ? 1 : 0);

function ofKind(value, kind) {
  switch (kind) {
    case 'any': return true;
    case 'boolean': return typeof value === 'boolean';
    case 'integer': return typeof value === 'number' && Number.isInteger(value);
    case 'number': return typeof value === 'number';
    case 'string': return typeof value === 'string';
    case 'array': return Array.isArray(value);
    case 'object': return isObject(value);
    default: return false;
  }
}

/** A checker over `types` (the table's named types). */
function makeCheckValue(types) {
  const resolve = (schema) => {
    if (!schema.ref) return schema;
    const named = types[schema.ref];
    if (!named) throw new Error(`protocol: no type named '${schema.ref}'`);
    return schema.nullable ? { ...named, nullable: true } : named;
  };

  const checkNumber = (s, value, path) => {
    if (!Number.isFinite(value)) return `${where(path)} must be a finite number`;
    const low = s.min !== undefined && value < s.min;
    const high = s.max !== undefined && value > s.max;
    if (!low && !high) return '';
    if (s.min !== undefined && s.max !== undefined) {
      return `${where(path)} must be in [${s.min}, ${s.max}], got ${JSON.stringify(value)}`;
    }
    return `${where(path)} must be at ${low ? 'least' : 'most'} ${low ? s.min : s.max}, got ${JSON.stringify(value)}`;
  };

  const checkArray = (s, value, path) => {
    const items = s.items ?? [];
    const tuple = items.length > 1;
    const length = tuple ? items.length : s.length;
    if (length !== undefined && value.length !== length) {
      return `${where(path)} must have ${length} items, got ${value.length}`;
    }
    if (items.length === 0) return '';
    for (let i = 0; i < value.length; i++) {
      const problem = check(tuple ? items[i] : items[0], value[i], `${path}[${i}]`);
      if (problem) return problem;
    }
    return '';
  };

  const checkObject = (s, value, path) => {
    const fields = s.fields ?? [];
    if (s.some && Object.keys(value).length === 0) {
      let what = fields.map((f) => f.name).join(', ');
      if (s.others) what += (what ? ' or ' : '') + s.others;
      return `${where(path)} must name at least one of ${what}`;
    }
    for (const f of fields) {
      if (!Object.hasOwn(value, f.name)) {
        if (f.required) return `missing field '${child(path, f.name)}'`;
        continue;
      }
      const problem = check(f.schema, value[f.name], child(path, f.name));
      if (problem) return problem;
    }
    const known = new Set(fields.map((f) => f.name));
    if (s.open) {
      if (!(s.items ?? []).length) return '';
      for (const key of Object.keys(value).sort(byName)) {
        if (known.has(key)) continue;
        const problem = check(s.items[0], value[key], child(path, key));
        if (problem) return problem;
      }
      return '';
    }
    for (const key of Object.keys(value).sort(byName)) {
      if (known.has(key)) continue;
      const names = fields.map((f) => f.name)
        .filter((n) => !(path === '' && (n === 'type' || n === 'id')));
      return `unknown field '${child(path, key)}'` + (names.length ? ` (expected ${names.join(', ')})` : '');
    }
    return '';
  };

  const check = (schema, value, path) => {
    const s = resolve(schema);
    if (s.kind === 'any' || (value === null && s.nullable)) return '';
    if (s.const !== undefined) {
      if (value === s.const) return '';
      const got = isObject(value) || Array.isArray(value) ? typeName(value) : JSON.stringify(value);
      return `${where(path)} must be ${JSON.stringify(s.const)}, got ${got}`;
    }
    if (!ofKind(value, s.kind)) {
      const got = typeof value === 'number' ? JSON.stringify(value) : typeName(value);
      return `${where(path)} must be ${kKindText[s.kind]}${s.nullable ? ' or null' : ''}, got ${got}`;
    }
    switch (s.kind) {
      case 'integer':
      case 'number':
        return checkNumber(s, value, path);
      case 'string':
        if (!s.values || s.values.includes(value)) return '';
        return `${where(path)} must be one of ${s.values.join(', ')}, got ${JSON.stringify(value)}`;
      case 'array':
        return checkArray(s, value, path);
      case 'object':
        return checkObject(s, value, path);
      default:
        return '';
    }
  };
  return check;
}

/** The checks of protocol.js over `table` (its types and messages). */
export function makeChecks(table) {
  const checkValue = makeCheckValue(table.types);
  const find = (channel, type) => table.messages.find((m) => m.channel === channel && m.type === type);
  const names = (channel) => table.messages.filter((m) => m.channel === channel).map((m) => m.type).join(', ');
  const hasType = (m) => isObject(m) && typeof m.type === 'string';

  const checkCommand = (command) => {
    if (!hasType(command)) return "a command must be an object with a string field 'type'";
    const m = find('command', command.type);
    if (!m) return `unknown command type '${command.type}' (${names('command')}: docs/gui-protocol.md)`;
    const problem = checkValue(m.body, command, '');
    return problem ? `${command.type}: ${problem}` : '';
  };

  const checkServerMessage = (message, command = '') => {
    if (!hasType(message)) return "a message must be an object with a string field 'type'";
    const m = find('text', message.type);
    if (!m) return `unknown message type '${message.type}' (${names('text')})`;
    if (message.type !== 'reply') {
      const problem = checkValue(m.body, message, '');
      return problem ? `${message.type}: ${problem}` : '';
    }
    // A reply: its envelope and the fields of its command's reply.
    const c = command ? find('command', command) : undefined;
    const body = c ? { ...m.body, fields: [...m.body.fields, ...c.reply] } : { ...m.body, open: true };
    const problem = checkValue(body, message, '');
    if (!problem) return '';
    return `${c ? `reply to ${c.type}` : 'reply'}: ${problem}`;
  };

  const checkFrameHeader = (header) => {
    const problem = checkValue(find('frame', 'frame').body, header, '');
    return problem ? `frame: ${problem}` : '';
  };

  const checkSceneDocument = (scene) => {
    const problem = checkValue(find('document', 'scene').body, scene, '');
    return problem ? `scene: ${problem}` : '';
  };

  return { checkValue, checkCommand, checkServerMessage, checkFrameHeader, checkSceneDocument };
}
