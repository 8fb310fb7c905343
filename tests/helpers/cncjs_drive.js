// Drives a running CNCjs server (npm `cncjs`, its own server and Grbl controller) as its web page
// does: Socket.IO with a token signed by the server's secret, the port opened with the Grbl
// controller, then one scenario. Prints what CNCjs saw as one `RESULT {json}` line.
//
//   node cncjs_drive.js URL SECRET PORT SCENARIO ARGS_JSON
//
// Scenarios (ARGS_JSON's keys):
//   stream     {file, holdAt, holdMs, before}: first each of `before` (["homing"] or
//              ["gcode", LINE]: CNCjs's Homing button, a line from its console or a button),
//              each to Idle; then gcode:load and gcode:start; with holdAt, a feed hold once
//              CNCjs counts that many lines acknowledged, and a cycle start holdMs after the hold
//   autolevel  {params}: CNCjs's height map (autolevel:start), to autolevel:complete
//   jog        {line, cancelMs}: a `$J=` line, then a jog cancel cancelMs after the state is Jog
// Needs socket.io-client and jsonwebtoken, which CNCjs brings (NODE_PATH: its node_modules).

'use strict';

const fs = require('fs');
const io = require('socket.io-client');
const jwt = require('jsonwebtoken');

const [url, secret, port, scenario, argsJson] = process.argv.slice(2);
const args = JSON.parse(argsJson || '{}');
const TIMEOUT_MS = 180000;

const seen = { states: [], errors: [], messages: [], status: null, sender: null, probed: [] };
let onState = () => {};

function finish(code, extra) {
  process.stdout.write('RESULT ' + JSON.stringify({ ...seen, ...extra }) + '\n');
  process.exit(code);
}

function waitFor(test) {
  // Resolves once a status report satisfies `test` (checked at once and at every report).
  return new Promise((resolve) => {
    const check = () => {
      if (seen.status && test(seen.status)) {
        onState = () => {};
        resolve(seen.status);
      }
    };
    onState = check;
    check();
  });
}

const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));
const token = jwt.sign({ id: '', name: '' }, secret, { expiresIn: '1h' });
const socket = io.connect(url, { query: 'token=' + token, reconnection: false });
const command = (...words) => socket.emit('command', port, ...words);

socket.on('controller:state', (type, state) => {
  seen.status = state.status;
  const name = state.status.activeState;
  if (seen.states[seen.states.length - 1] !== name) seen.states.push(name);
  onState();
});
let oks = 0;
socket.on('serialport:read', (line) => {
  if (line === 'ok') oks += 1;
  if (/^(error|ALARM):/.test(line)) seen.errors.push(line);
  if (/^\[(MSG|PRB):/.test(line)) seen.messages.push(line);
});
socket.on('sender:status', (status) => {
  seen.sender = { sent: status.sent, received: status.received, total: status.total };
});
socket.on('autolevel:update', (update) => seen.probed.push(update.probedPos));
socket.on('connect_error', (error) => finish(3, { failure: 'connect: ' + error }));
setTimeout(() => finish(4, { failure: 'timed out' }), TIMEOUT_MS);

async function stream() {
  for (const words of args.before || []) {
    const [ran, answered] = [seen.states.length, oks];
    command(...words);
    if (words[0] === 'homing') await waitFor((s) => seen.states.length > ran && s.activeState === 'Idle');
    else while (oks === answered) await sleep(10);
  }
  command('gcode:load', 'job.nc', fs.readFileSync(args.file, 'utf8'), {});
  await sleep(200);
  command('gcode:start');
  if (args.holdAt !== undefined) {
    while (!seen.sender || seen.sender.received < args.holdAt) await sleep(5);
    command('feedhold');
    await waitFor((s) => s.activeState === 'Hold');
    await sleep(args.holdMs);
    command('cyclestart');
  }
  while (!seen.sender || seen.sender.received < seen.sender.total) await sleep(20);
  await sleep(500);
  return waitFor((s) => s.activeState === 'Idle');
}

async function autolevel() {
  const complete = new Promise((resolve) => socket.on('autolevel:complete', resolve));
  command('autolevel:start', args.params);
  await complete;
  return waitFor((s) => s.activeState === 'Idle');
}

async function jog() {
  command('gcode', args.line);
  await waitFor((s) => s.activeState === 'Jog');
  await sleep(args.cancelMs);
  command('jogCancel');
  await sleep(300);
  return waitFor((s) => s.activeState === 'Idle');
}

const SCENARIOS = { stream, autolevel, jog };

socket.on('connect', () => {
  socket.emit('open', port, { controllerType: 'Grbl', baudrate: 115200 }, async (error) => {
    if (error) finish(2, { failure: 'open: ' + error });
    await waitFor((s) => s.activeState === 'Idle'); // the banner came and CNCjs polls `?`
    await SCENARIOS[scenario]();
    finish(0, {});
  });
});
