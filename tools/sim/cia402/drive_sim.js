#!/usr/bin/env node
'use strict';
// Simulated CiA 402 drives on one SocketCAN bus, for the runtime's CANopen
// manager. One process holds every drive; cdcr-can-relay carries the frames
// between the bus and this process as text lines (III#HEX).
//
//   node drive_sim.js --can vcan0 --nodes 1,2,3,4 [--relay PATH] [--tau-ms 2]
//        [--play-counts 0] [--initial-counts 0] [--fault KIND:NODE[:ARG][@MS]]...
//
//   node drive_sim.js --stdio --nodes 1,2,3,4 ...
//        the same lines on stdin and stdout instead of a bus: a test's bus.
//        A line "#" is a barrier: once every frame before it was taken, the
//        drives' answers go out, then "#".
//
// Fault kinds: heartbeat-stop, emcy:NODE:CODE (hex), refuse:NODE:INDEX (hex),
// silent, tpdo-late:NODE:N, tpdo-twice. @MS counts from the first NMT start
// seen on the bus; for refuse and silent from the start of this process.
// @usr2 instead: on a SIGUSR2, one such fault each, in the order given (a
// test injects a fault when it has seen what comes before it).

const { spawn } = require('child_process');
const { Cia402Drive } = require('./cia402_layer');

const USAGE = 'usage: node drive_sim.js (--can IFACE | --stdio) --nodes N[,N...] [--relay PATH] [--tau-ms MS] ' +
    '[--play-counts C] [--initial-counts C[,C...]] [--fault KIND:NODE[:ARG][@MS|@usr2]]...';
const FAULT_KINDS = ['heartbeat-stop', 'emcy', 'refuse', 'silent', 'tpdo-late', 'tpdo-twice'];
const FROM_PROCESS_START = new Set(['refuse', 'silent']);

function log(text) {
    process.stderr.write(`drive_sim: ${text}\n`);
}

function usageError(text) {
    process.stderr.write(`drive_sim: ${text} (--help for usage)\n`);
    process.exit(2);
}

function parseNumber(text, what, { integer = false, min = -Infinity, max = Infinity } = {}) {
    const value = Number(text);
    if (text === undefined || text === '' || !Number.isFinite(value) || (integer && !Number.isInteger(value)) ||
        value < min || value > max)
        usageError(`${what}: '${text}' is not a ${integer ? 'whole ' : ''}number in [${min}, ${max}]`);
    return value;
}

function parseHex(text, what, max) {
    if (!/^(0x)?[0-9a-fA-F]{1,8}$/.test(text || '')) usageError(`${what}: '${text}' is not hexadecimal`);
    const value = parseInt(text.replace(/^0x/, ''), 16);
    if (value > max) usageError(`${what}: ${text} is beyond 0x${max.toString(16)}`);
    return value;
}

function parseFault(text, nodes) {
    const match = /^([a-z-]+):(\d+)(?::([^@]+))?(?:@(\d+|usr2))?$/.exec(text);
    if (!match) usageError(`--fault '${text}': expected KIND:NODE[:ARG][@MS|@usr2]`);
    const [, kind, nodeText, arg, msText] = match;
    if (!FAULT_KINDS.includes(kind)) usageError(`--fault '${text}': kind is one of ${FAULT_KINDS.join(', ')}`);
    const node = parseNumber(nodeText, `--fault '${text}' node`, { integer: true, min: 1, max: 127 });
    if (!nodes.includes(node)) usageError(`--fault '${text}': node ${node} is not in --nodes`);
    const onSignal = msText === 'usr2';
    const fault = { kind, node, onSignal, atMs: msText === undefined || onSignal ? 0 : Number(msText), text };
    const needsArg = kind === 'emcy' || kind === 'refuse' || kind === 'tpdo-late';
    if (needsArg && arg === undefined) usageError(`--fault '${text}': ${kind} takes an argument`);
    if (!needsArg && arg !== undefined) usageError(`--fault '${text}': ${kind} takes no argument`);
    if (kind === 'emcy') {
        fault.code = parseHex(arg, `--fault '${text}' error code`, 0xFFFF);
        if (fault.code === 0) usageError(`--fault '${text}': error code 0 is "no error"`);
    } else if (kind === 'refuse') {
        fault.index = parseHex(arg, `--fault '${text}' object index`, 0xFFFF);
    } else if (kind === 'tpdo-late') {
        fault.count = parseNumber(arg, `--fault '${text}' SYNC count`, { integer: true, min: 1, max: 1e6 });
    }
    return fault;
}

function parseArguments(argv) {
    const options = {
        can: null, stdio: false, nodes: null, relay: process.env.CDCR_CAN_RELAY || 'cdcr-can-relay',
        tauMs: 2, playCounts: 0, initialCounts: [0], faults: [],
    };
    const faultTexts = [];
    for (let i = 0; i < argv.length; ++i) {
        const option = argv[i];
        const value = argv[i + 1];
        const takeValue = () => {
            if (value === undefined || value.startsWith('--')) usageError(`${option} needs a value`);
            ++i;
            return value;
        };
        switch (option) {
            case '--can': options.can = takeValue(); break;
            case '--stdio': options.stdio = true; break;
            case '--nodes':
                options.nodes = takeValue().split(',').map((n) => parseNumber(n, '--nodes', { integer: true, min: 1, max: 127 }));
                break;
            case '--relay': options.relay = takeValue(); break;
            case '--tau-ms': options.tauMs = parseNumber(takeValue(), '--tau-ms', { min: 0, max: 1e6 }); break;
            case '--play-counts': options.playCounts = parseNumber(takeValue(), '--play-counts', { min: 0, max: 1e9 }); break;
            case '--initial-counts':
                options.initialCounts = takeValue().split(',').map((c) =>
                    parseNumber(c, '--initial-counts', { integer: true, min: -2147483648, max: 2147483647 }));
                break;
            case '--fault': faultTexts.push(takeValue()); break;
            case '-h': case '--help': process.stdout.write(USAGE + '\n'); process.exit(0); break;
            default: usageError(`unknown option '${option}'`);
        }
    }
    if (!options.can === !options.stdio) usageError('one of --can and --stdio is required');
    if (!options.nodes) usageError('--nodes is required');
    if (new Set(options.nodes).size !== options.nodes.length) usageError('--nodes: a node id twice');
    if (options.initialCounts.length !== 1 && options.initialCounts.length !== options.nodes.length)
        usageError('--initial-counts: one value, or one per node');
    options.faults = faultTexts.map((text) => parseFault(text, options.nodes));
    return options;
}

// ---- frames as lines ----

function parseLine(line) {
    const match = /^([0-9A-Fa-f]{3})#((?:[0-9A-Fa-f]{2}){0,8})$/.exec(line);
    if (!match) return null;  // extended and remote frames are not CANopen's here
    return { id: parseInt(match[1], 16), data: Buffer.from(match[2], 'hex') };
}

function formatFrame({ id, data }) {
    return id.toString(16).toUpperCase().padStart(3, '0') + '#' + data.toString('hex').toUpperCase();
}

function main() {
    const options = parseArguments(process.argv.slice(2));
    const drives = new Map();
    options.nodes.forEach((node, i) => {
        const initialCounts = options.initialCounts.length === 1 ? options.initialCounts[0] : options.initialCounts[i];
        drives.set(node, new Cia402Drive({ node, tauMs: options.tauMs, playCounts: options.playCounts, initialCounts }));
    });

    // The bus: the relay's pipes, or this process's own with --stdio.
    const relay = options.stdio
        ? { stdin: process.stdout, stdout: process.stdin, on() {}, kill() {} }
        : spawn(options.relay, [options.can], { stdio: ['pipe', 'pipe', 'inherit'] });
    let stopping = false;
    relay.on('error', (error) => {
        log(`cannot run the relay '${options.relay}': ${error.message}`);
        process.exit(1);
    });
    relay.on('exit', (code, signal) => {
        if (stopping) process.exit(0);
        log(`the relay ended (${signal || 'exit status ' + code})`);
        process.exit(1);
    });
    relay.stdin.on('error', (error) => {
        if (!stopping) log(`writing to the relay: ${error.message}`);
    });

    // Frames the drives send in one turn of the event loop go out in one write.
    let outgoing = [];
    const flush = () => {
        const text = outgoing.join('');
        outgoing = [];
        if (text && !relay.stdin.destroyed) relay.stdin.write(text);
    };
    const send = (frame) => {
        if (outgoing.length === 0) process.nextTick(flush);
        outgoing.push(formatFrame(frame) + '\n');
    };

    for (const [node, drive] of drives) {
        drive.on('frame', send);
        drive.on('event', (text) => log(`node ${node}: ${text}`));
    }

    // ---- faults ----
    const inject = (fault) => {
        const drive = drives.get(fault.node);
        switch (fault.kind) {
            case 'heartbeat-stop': drive.stopHeartbeat(); break;
            case 'emcy': drive.emergency(fault.code); break;
            case 'refuse': drive.refuseWrite(fault.index); break;
            case 'silent': drive.setSilent(true); break;
            case 'tpdo-late': drive.lateTpdo(fault.count); break;
            case 'tpdo-twice': drive.twiceTpdo(true); break;
        }
    };
    const schedule = (faults) => {
        for (const fault of faults) {
            if (fault.atMs === 0) inject(fault);
            else setTimeout(() => inject(fault), fault.atMs);
        }
    };
    const onSignal = options.faults.filter((f) => f.onSignal);
    process.on('SIGUSR2', () => {
        const fault = onSignal.shift();
        if (fault) inject(fault);
        else log('SIGUSR2: no fault left to inject');
    });
    const timed = options.faults.filter((f) => !f.onSignal);
    schedule(timed.filter((f) => FROM_PROCESS_START.has(f.kind)));
    const afterStart = timed.filter((f) => !FROM_PROCESS_START.has(f.kind));
    let started = false;
    for (const drive of drives.values()) {
        drive.on('nmtStart', () => {
            if (started) return;
            started = true;
            log('first NMT start');
            schedule(afterStart);
        });
    }

    // ---- frames in ----
    let pending = '';
    let atBarrier = false;
    let inputEnded = false;
    const deliver = (frame) => {
        const node = frame.id & 0x7F;
        if (node === 0) {
            for (const drive of drives.values()) drive.receive(frame);
        } else {
            const drive = drives.get(node);
            if (drive) drive.receive(frame);
        }
    };
    // Takes the lines received so far; at a barrier ("#", --stdio) it stops
    // until what the stack deferred with setImmediate (its NMT reset) has run
    // and the answers are out, then answers "#" and goes on.
    const drain = () => {
        let start = 0;
        for (let end; (end = pending.indexOf('\n', start)) !== -1; start = end + 1) {
            const line = pending.slice(start, end);
            if (options.stdio && line === '#') {
                pending = pending.slice(end + 1);
                atBarrier = true;
                setImmediate(() => {
                    flush();
                    relay.stdin.write('#\n');
                    atBarrier = false;
                    drain();
                });
                return;
            }
            const frame = parseLine(line);
            if (frame) deliver(frame);
        }
        pending = pending.slice(start);
        if (inputEnded) setImmediate(() => { flush(); process.exit(0); });
    };
    relay.stdout.setEncoding('latin1');
    relay.stdout.on('data', (chunk) => {
        pending += chunk;
        if (!atBarrier) drain();
    });
    if (options.stdio) {
        process.stdin.on('end', () => {
            inputEnded = true;
            if (!atBarrier) drain();
        });
    }

    for (const drive of drives.values()) drive.start();
    log(`${drives.size} drive(s) on ${options.stdio ? 'stdio' : options.can}: nodes ${options.nodes.join(',')}, tau ${options.tauMs} ms, ` +
        `play ${options.playCounts} counts`);

    const shutdown = (signal) => {
        if (stopping) return;
        stopping = true;
        log(`${signal}: stopping`);
        for (const drive of drives.values()) drive.stop();
        flush();
        relay.stdin.end();
        // The relay ends when its stdin closes; if it does not, it is ended.
        setTimeout(() => relay.kill('SIGTERM'), 500).unref();
        setTimeout(() => process.exit(0), 1000).unref();
    };
    process.on('SIGTERM', () => shutdown('SIGTERM'));
    process.on('SIGINT', () => shutdown('SIGINT'));
}

if (require.main === module) main();

module.exports = { parseLine, formatFrame, parseFault };
