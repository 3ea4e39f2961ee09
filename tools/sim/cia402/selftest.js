#!/usr/bin/env node
'use strict';
// The drive layer without a CAN bus: two drives in this process, driven with
// frames written out byte by byte from CiA 301 / CiA 402, in the order the
// runtime's manager sends them. Exit status 0 when every check holds.

const { Cia402Drive } = require('./cia402_layer');

let failures = 0;
let checks = 0;
function check(condition, what, detail = '') {
    ++checks;
    if (condition) return;
    ++failures;
    console.log(`FAIL ${what}${detail ? ': ' + detail : ''}`);
}

const hex = (data) => Buffer.from(data).toString('hex');
const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));
const nextTurn = () => new Promise((resolve) => setImmediate(resolve));

// ---- the bus ----
const drives = new Map();
let sent = [];  // what the drives sent: { id, data, t }
function addDrive(options) {
    const drive = new Cia402Drive(options);
    drive.on('frame', ({ id, data }) => sent.push({ id, data, t: Date.now() }));
    drives.set(options.node, drive);
    return drive;
}
// To the drives, routed as on a bus: node 0 to every drive.
function busSend(id, bytes) {
    const data = Buffer.from(bytes);
    const node = id & 0x7F;
    for (const [n, drive] of drives) if (node === 0 || node === n) drive.receive({ id, data });
}
function takeSent(filter = () => true) {
    const taken = sent.filter(filter);
    sent = sent.filter((f) => !filter(f));
    return taken;
}

// ---- frames, from the specifications ----
const le16 = (v) => [v & 0xFF, (v >>> 8) & 0xFF];
const le32 = (v) => [v & 0xFF, (v >>> 8) & 0xFF, (v >>> 16) & 0xFF, (v >>> 24) & 0xFF];
// Expedited download: ccs 1, n = unused bytes, e = 1, s = 1 → 0x2F / 0x2B / 0x23.
const DOWNLOAD_COMMAND = { 1: 0x2F, 2: 0x2B, 4: 0x23 };
function sdoDownload(node, index, sub, valueBytes) {
    const payload = [...valueBytes, 0, 0, 0, 0].slice(0, 4);
    busSend(0x600 + node, [DOWNLOAD_COMMAND[valueBytes.length], ...le16(index), sub, ...payload]);
}
function sdoUpload(node, index, sub) {
    busSend(0x600 + node, [0x40, ...le16(index), sub, 0, 0, 0, 0]);
}
function sdoReplies(node) {
    return takeSent((f) => f.id === 0x580 + node);
}
function expectDownloadDone(node, index, sub, what) {
    const replies = sdoReplies(node);
    check(replies.length === 1 && hex(replies[0].data) === hex([0x60, ...le16(index), sub, 0, 0, 0, 0]),
        `SDO download reply 0x60 for ${what} on node ${node}`, replies.map((r) => hex(r.data)).join(' '));
}
function expectAbort(node, index, sub, code, what) {
    const replies = sdoReplies(node);
    check(replies.length === 1 && hex(replies[0].data) === hex([0x80, ...le16(index), sub, ...le32(code)]),
        `SDO abort ${code.toString(16)} for ${what} on node ${node}`, replies.map((r) => hex(r.data)).join(' '));
}
function uploadValue(node, index, sub) {
    sdoUpload(node, index, sub);
    const replies = sdoReplies(node);
    if (replies.length !== 1 || (replies[0].data[0] & 0xE2) !== 0x42) return undefined;
    return replies[0].data;
}

// The manager's configuration writes, cia402.hpp order, written out.
function configure(node, { cyclePeriodUs = 1000, syncWindowUs = 500, heartbeatMs = 50 } = {}) {
    const writes = [
        [0x1400, 1, le32((0x80000000 | (0x200 + node)) >>> 0)],
        [0x1600, 0, [0]],
        [0x1600, 1, le32(0x60400010)],
        [0x1600, 2, le32(0x607A0020)],
        [0x1600, 0, [2]],
        [0x1400, 2, [1]],
        [0x1400, 1, le32(0x200 + node)],
        [0x1800, 1, le32((0x80000000 | (0x180 + node)) >>> 0)],
        [0x1A00, 0, [0]],
        [0x1A00, 1, le32(0x60410010)],
        [0x1A00, 2, le32(0x60640020)],
        [0x1A00, 0, [2]],
        [0x1800, 2, [1]],
        [0x1800, 1, le32(0x180 + node)],
        [0x6060, 0, [8]],
        [0x1006, 0, le32(cyclePeriodUs)],
        [0x1007, 0, le32(syncWindowUs)],
        [0x1017, 0, le16(heartbeatMs)],
    ];
    for (const [index, sub, bytes] of writes) {
        sdoDownload(node, index, sub, bytes);
        expectDownloadDone(node, index, sub, `${index.toString(16)}:${sub}`);
    }
}

// One manager cycle: RPDO1 [controlword u16, target i32] per drive, then SYNC.
// Returns each drive's TPDOs sent after that SYNC.
function cycle(commands) {
    takeSent((f) => (f.id & 0x780) === 0x180);
    for (const [node, controlword, target] of commands)
        busSend(0x200 + node, [...le16(controlword), ...le32(target)]);
    busSend(0x080, []);
    const tpdos = {};
    for (const f of takeSent((f) => (f.id & 0x780) === 0x180)) (tpdos[f.id & 0x7F] ||= []).push(f.data);
    return tpdos;
}
const statusOf = (data) => data.readUInt16LE(0);
const positionOf = (data) => data.readInt32LE(2);

async function main() {
    const one = addDrive({ node: 1, tauMs: 2, initialCounts: 1000 });
    const two = addDrive({ node: 2, tauMs: 2, initialCounts: -500, playCounts: 100 });

    // ---- boot ----
    one.start();
    two.start();
    check(hex(takeSent((f) => f.id === 0x701).map((f) => f.data)[0] || []) === '00', 'boot-up 0x701 [00] at start');
    check(takeSent((f) => f.id === 0x702 && hex(f.data) === '00').length === 1, 'boot-up 0x702 [00] at start');

    // Before the manager: the default mapping is not the manager's.
    check(hex(uploadValue(1, 0x1A00, 0) || []) === hex([0x4F, 0x00, 0x1A, 0x00, 1, 0, 0, 0]),
        'default TPDO1 maps one object (upload 0x4F)');
    sdoDownload(1, 0x6060, 0, [8]);  // a value the reset must undo
    sdoReplies(1);

    // ---- 1. reset communication, boot-up ----
    busSend(0x000, [0x82, 0x00]);
    check(takeSent((f) => (f.id & 0x780) === 0x700).length === 0, 'no boot-up before the reset has happened');
    await nextTurn();
    const boots = takeSent((f) => (f.id & 0x780) === 0x700);
    check(boots.length === 2 && boots.every((f) => hex(f.data) === '00'), 'both boot-ups after reset communication',
        boots.map((f) => f.id.toString(16) + ':' + hex(f.data)).join(' '));
    check(hex(uploadValue(1, 0x6060, 0) || []) === hex([0x4F, 0x60, 0x60, 0x00, 8, 0, 0, 0]),
        'reset communication keeps the application (0x6060 still 8)');

    // ---- 2. configuration ----
    configure(1);
    configure(2);
    check(hex(uploadValue(1, 0x6061, 0) || []) === hex([0x4F, 0x61, 0x60, 0x00, 8, 0, 0, 0]), '0x6061 mirrors 0x6060');
    sdoDownload(1, 0x6060, 0, [1]);
    expectAbort(1, 0x6060, 0, 0x06090030, '0x6060 = 1 (profile position)');
    sdoDownload(1, 0x6041, 0, le16(0x0237));
    expectAbort(1, 0x6041, 0, 0x06010002, 'read-only statusword');
    sdoDownload(1, 0x6060, 0, le32(8));
    expectAbort(1, 0x6060, 0, 0x06070010, '4 bytes to a 1-byte object');
    sdoDownload(1, 0x1A00, 3, le32(0x10000020));  // device type: not mappable
    expectAbort(1, 0x1A00, 3, 0x06040041, 'mapping a non-mappable object');

    // ---- PDOs and SYNC wait for NMT operational ----
    check(Object.keys(cycle([[1, 0x06, 1000]])).length === 0, 'no TPDO in pre-operational');
    check(one.statusword === 0x0250, 'no power transition from an RPDO in pre-operational', one.statusword.toString(16));

    // ---- 3. NMT start, heartbeats ----
    busSend(0x000, [0x01, 0x00]);
    takeSent((f) => (f.id & 0x780) === 0x700);
    const t0 = Date.now();
    await sleep(265);
    const beats = takeSent((f) => f.id === 0x701);
    const gaps = beats.slice(1).map((f, i) => f.t - beats[i].t);
    check(beats.length >= 4 && beats.length <= 6 && beats.every((f) => hex(f.data) === '05'),
        'heartbeats [05] every 50 ms', `${beats.length} in ${Date.now() - t0} ms`);
    check(gaps.every((g) => g >= 35 && g <= 70), 'heartbeat gaps near 50 ms', gaps.join(','));

    // ---- 4. enabling: transitions 2, 3, 4 ----
    let tpdos = cycle([[1, 0x06, 1000], [2, 0x06, -500]]);
    check(tpdos[1] && tpdos[1].length === 1 && tpdos[1][0].length === 6, 'remapped TPDO1 has 6 bytes',
        tpdos[1] && hex(tpdos[1][0]));
    check(tpdos[1] && statusOf(tpdos[1][0]) === 0x0231, 'shutdown → ready to switch on 0x0231',
        tpdos[1] && statusOf(tpdos[1][0]).toString(16));
    tpdos = cycle([[1, 0x07, 1000], [2, 0x07, -500]]);
    check(tpdos[1] && statusOf(tpdos[1][0]) === 0x0233, 'switch on → switched on 0x0233');
    tpdos = cycle([[1, 0x07, 1000], [2, 0x07, -500]]);
    check(tpdos[1] && statusOf(tpdos[1][0]) === 0x0233, 'switch on again: stays switched on');
    tpdos = cycle([[1, 0x0F, 1000], [2, 0x0F, -500]]);
    check(tpdos[1] && (statusOf(tpdos[1][0]) & ~0x0400) === 0x0237 && positionOf(tpdos[1][0]) === 1000,
        'enable operation → 0x0237 and the position', tpdos[1] && hex(tpdos[1][0]));
    check(tpdos[2] && (statusOf(tpdos[2][0]) & ~0x0400) === 0x0237 && positionOf(tpdos[2][0]) === -500,
        'node 2 enabled where it stands', tpdos[2] && hex(tpdos[2][0]));
    check(tpdos[1] && (statusOf(tpdos[1][0]) & 0x0400) !== 0, 'target reached (bit 10) when on target');

    // ---- the position loop ----
    let previous = 1000;
    let approaching = true;
    for (let i = 0; i < 20; ++i) {
        tpdos = cycle([[1, 0x0F, 6000], [2, 0x0F, 1500]]);
        const position = positionOf(tpdos[1][0]);
        // Rounded to counts, the last steps may be none; never back, never beyond.
        if (!(position >= previous && position <= 6000) || (i === 0 && position === previous)) approaching = false;
        previous = position;
    }
    check(approaching, 'position moves toward the target every SYNC');
    check(Math.abs(previous - 6000) <= 1, 'position converges to the target in 10 tau', String(previous));
    // First order, tau 2 ms, 1 ms a SYNC: after one SYNC 1 - e^-0.5 of the step.
    tpdos = cycle([[1, 0x0F, 7000], [2, 0x0F, 1500]]);
    const expected = 6000 + 1000 * (1 - Math.exp(-0.5));
    check(Math.abs(positionOf(tpdos[1][0]) - expected) <= 1, 'one SYNC of the first-order loop',
        `${positionOf(tpdos[1][0])} vs ${expected.toFixed(1)}`);
    // The cable play of node 2 (100 counts): the cable end stays 50 behind.
    check(Math.abs(positionOf(tpdos[2][0]) - 1450) <= 1, 'cable end lags the motor by half the play',
        String(positionOf(tpdos[2][0])));
    for (let i = 0; i < 20; ++i) tpdos = cycle([[1, 0x0F, 7000], [2, 0x0F, 1420]]);
    check(Math.abs(positionOf(tpdos[2][0]) - 1450) <= 1, 'a reversal within the play leaves the cable end',
        String(positionOf(tpdos[2][0])));

    // ---- dynamic remapping while operational ----
    sdoDownload(1, 0x1800, 1, le32((0x80000000 | 0x181) >>> 0));
    expectDownloadDone(1, 0x1800, 1, 'TPDO1 invalid while operational');
    tpdos = cycle([[1, 0x0F, 7000], [2, 0x0F, 1420]]);
    check(!tpdos[1] && tpdos[2], 'no TPDO1 once its COB-ID is invalid');
    sdoDownload(1, 0x1A00, 0, [1]);
    sdoReplies(1);
    sdoDownload(1, 0x1800, 1, le32(0x181));
    sdoReplies(1);
    tpdos = cycle([[1, 0x0F, 7000], [2, 0x0F, 1420]]);
    check(tpdos[1] && tpdos[1][0].length === 2, 'TPDO1 remapped while operational: 2 bytes', tpdos[1] && hex(tpdos[1][0]));
    sdoDownload(1, 0x1800, 1, le32((0x80000000 | 0x181) >>> 0));
    sdoDownload(1, 0x1A00, 0, [2]);
    sdoDownload(1, 0x1800, 1, le32(0x181));
    sdoReplies(1);
    tpdos = cycle([[1, 0x0F, 7000], [2, 0x0F, 1420]]);
    check(tpdos[1] && tpdos[1][0].length === 6, 'and back to 6 bytes');

    // ---- refused object ----
    two.refuseWrite(0x1017);
    sdoDownload(2, 0x1017, 0, le16(50));
    expectAbort(2, 0x1017, 0, 0x06010002, 'a refused object');

    // ---- EMCY and fault ----
    takeSent((f) => f.id === 0x081);
    one.emergency(0x2310);
    const emcy = takeSent((f) => f.id === 0x081);
    check(emcy.length === 1 && hex(emcy[0].data) === hex([0x10, 0x23, 0x01, 0, 0, 0, 0, 0]), 'EMCY 0x081 bytes',
        emcy.map((f) => hex(f.data)).join(' '));
    tpdos = cycle([[1, 0x0F, 7000], [2, 0x0F, 1420]]);
    check(tpdos[1] && statusOf(tpdos[1][0]) === 0x0218, 'fault statusword 0x0218 after the EMCY');
    const faultPosition = positionOf(tpdos[1][0]);

    // Reset communication (of node 1 alone) keeps the fault and the position.
    busSend(0x000, [0x82, 0x01]);
    await nextTurn();
    check(takeSent((f) => f.id === 0x701 && hex(f.data) === '00').length === 1, 'boot-up after the second reset');
    check(two.nmtState === 5, 'a reset addressed to node 1 leaves node 2 operational');
    check(hex(uploadValue(1, 0x6064, 0) || []) === hex([0x43, 0x64, 0x60, 0x00, ...le32(faultPosition)]),
        'position survives reset communication');
    check(hex(uploadValue(1, 0x6041, 0) || []) === hex([0x4B, 0x41, 0x60, 0x00, 0x18, 0x02, 0, 0]),
        'fault survives reset communication');
    check(hex(uploadValue(1, 0x1017, 0) || []) === hex([0x4B, 0x17, 0x10, 0x00, 0, 0, 0, 0]),
        'reset communication restores the heartbeat time to 0');
    check(hex(uploadValue(1, 0x1A00, 0) || []) === hex([0x4F, 0x00, 0x1A, 0x00, 1, 0, 0, 0]),
        'reset communication restores the default mapping');
    configure(1);
    busSend(0x000, [0x01, 0x01]);
    takeSent((f) => (f.id & 0x780) === 0x700);
    // The manager's fault reset: 0x80 alternating with 0x00.
    tpdos = cycle([[1, 0x80, faultPosition]]);
    check(tpdos[1] && statusOf(tpdos[1][0]) === 0x0250, 'fault reset (bit 7 rising) → switch on disabled');
    const clear = takeSent((f) => f.id === 0x081);
    check(clear.length === 1 && hex(clear[0].data) === '0000000000000000', 'EMCY error reset 0000 after the fault reset');
    tpdos = cycle([[1, 0x80, faultPosition]]);
    check(tpdos[1] && statusOf(tpdos[1][0]) === 0x0250, 'bit 7 held high is no second reset');

    // ---- quick stop ----
    cycle([[1, 0x06, faultPosition]]);
    cycle([[1, 0x07, faultPosition]]);
    cycle([[1, 0x0F, faultPosition]]);
    tpdos = cycle([[1, 0x02, faultPosition + 5000]]);
    check(tpdos[1] && (statusOf(tpdos[1][0]) & ~0x0400) === 0x0217 && positionOf(tpdos[1][0]) === faultPosition,
        'quick stop → 0x0217, holding', tpdos[1] && hex(tpdos[1][0]));
    tpdos = cycle([[1, 0x00, faultPosition]]);
    check(tpdos[1] && statusOf(tpdos[1][0]) === 0x0250, 'disable voltage from quick stop → switch on disabled');

    // ---- late and repeated TPDOs ----
    two.lateTpdo(1);
    tpdos = cycle([[2, 0x0F, 1420]]);
    check(!tpdos[2], 'a late TPDO: none after its SYNC');
    tpdos = cycle([[2, 0x0F, 1420]]);
    check(tpdos[2] && tpdos[2].length === 2, 'a late TPDO: two after the next SYNC', tpdos[2] && String(tpdos[2].length));
    two.twiceTpdo(true);
    tpdos = cycle([[2, 0x0F, 1420]]);
    check(tpdos[2] && tpdos[2].length === 2 && hex(tpdos[2][0]) === hex(tpdos[2][1]), 'every TPDO twice');
    two.twiceTpdo(false);

    // ---- heartbeat stop, silence ----
    takeSent();
    two.stopHeartbeat();
    await sleep(120);
    check(takeSent((f) => f.id === 0x702).length === 0, 'no heartbeat once stopped');
    two.setSilent(true);
    sdoUpload(2, 0x1000, 0);
    busSend(0x000, [0x82, 0x02]);
    await nextTurn();
    check(takeSent((f) => (f.id & 0x7F) === 2).length === 0, 'a silent drive answers nothing, not even a reset');

    // ---- reset node: application back to defaults, the motor stays ----
    const before = one.positionCounts;
    busSend(0x000, [0x81, 0x01]);
    await nextTurn();
    check(takeSent((f) => f.id === 0x701 && hex(f.data) === '00').length === 1, 'boot-up after reset node');
    check(hex(uploadValue(1, 0x6060, 0) || []) === hex([0x4F, 0x60, 0x60, 0x00, 0, 0, 0, 0]),
        'reset node restores 0x6060 to its default');
    check(one.positionCounts === before, 'reset node leaves the position', `${one.positionCounts} vs ${before}`);
    check(hex(uploadValue(1, 0x1000, 0) || []) === hex([0x43, 0x00, 0x10, 0x00, ...le32(0x00020192)]),
        'device type 0x00020192 after reset node');

    one.stop();
    two.stop();
    console.log(`${checks - failures}/${checks} checks passed`);
    process.exit(failures === 0 ? 0 : 1);
}

main().catch((error) => {
    console.log(`FAIL ${error.stack}`);
    process.exit(1);
});
