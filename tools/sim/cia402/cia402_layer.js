'use strict';
// A simulated CiA 402 drive in cyclic synchronous position mode, built on
// one canopen@6.2.1 Device. The stack answers SDOs, sends heartbeats, EMCYs
// and the TPDOs a SYNC releases; this layer adds what a real CiA 301/402
// drive does and the stack does not:
//   - the boot-up message, after start and after every NMT reset, once the
//     object dictionary holds its reset values again;
//   - CiA 301 reset semantics: reset communication restores 0x1000-0x1FFF
//     only (the stack resets every VAR and no RECORD), reset node also the
//     application, and neither moves the motor;
//   - the PDO mapping re-read when a PDO's parameters change while the PDO
//     module runs (the stack reads them only when it starts);
//   - SDO checks the stack leaves out: the length of an expedited download,
//     the PDO mapping entries, the only supported mode of operation;
//   - the power state machine and the position loop, run on each SYNC
//     before the stack sends that SYNC's TPDOs;
//   - injectable faults.
// Frames come in through receive(frame) and leave as 'frame' events; notable
// changes are 'event' events with one line of text.

const EventEmitter = require('events');
const { AccessType, DataType, Device, Eds, NmtState, ObjectType } = require('canopen');

// ---- CiA 301 ----
const NMT_ID = 0x000;
const NMT_START = 0x01;
const NMT_RESET_NODE = 0x81;
const NMT_RESET_COMMUNICATION = 0x82;
const BOOT_UP_BASE = 0x700;
const SDO_ABORT = 0x80;

const ABORT_READ_ONLY = 0x06010002;
const ABORT_NOT_MAPPABLE = 0x06040041;
const ABORT_MAP_LENGTH = 0x06040042;
const ABORT_LENGTH_MISMATCH = 0x06070010;
const ABORT_VALUE_RANGE = 0x06090030;

const MAPPING_ENTRIES = 8;  // per PDO: 64 bits of 8-bit objects at most
const PDO_PARAMETER_FIRST = 0x1400;
const PDO_PARAMETER_LAST = 0x1BFF;

// ---- CiA 402 ----
const DEVICE_TYPE_SERVO = 0x00020192;  // CiA 402, servo drive
const MODE_CSP = 8;

const PowerState = Object.freeze({
    SWITCH_ON_DISABLED: 'switch on disabled',
    READY_TO_SWITCH_ON: 'ready to switch on',
    SWITCHED_ON: 'switched on',
    OPERATION_ENABLED: 'operation enabled',
    QUICK_STOP_ACTIVE: 'quick stop active',
    FAULT: 'fault',
});

// Statusword bits 0-6 and 9 (remote) of each state, CiA 402-2 table 30.
const STATUSWORD = Object.freeze({
    [PowerState.SWITCH_ON_DISABLED]: 0x0250,
    [PowerState.READY_TO_SWITCH_ON]: 0x0231,
    [PowerState.SWITCHED_ON]: 0x0233,
    [PowerState.OPERATION_ENABLED]: 0x0237,
    [PowerState.QUICK_STOP_ACTIVE]: 0x0217,
    [PowerState.FAULT]: 0x0218,
});
const STATUS_TARGET_REACHED = 0x0400;  // bit 10
const CONTROL_FAULT_RESET = 0x0080;    // bit 7, acts on its rising edge

// The controlword commands, CiA 402-2 table 28: the bits each one looks at, and their values.
const isShutdown = (cw) => (cw & 0x87) === 0x06;
const isSwitchOn = (cw) => (cw & 0x87) === 0x07;  // bit 3 decides whether enable follows
const isDisableVoltage = (cw) => (cw & 0x82) === 0x00;
const isQuickStop = (cw) => (cw & 0x86) === 0x02;
const isDisableOperation = (cw) => (cw & 0x8F) === 0x07;
const isEnableOperation = (cw) => (cw & 0x8F) === 0x0F;

const hex = (value, digits) => '0x' + value.toString(16).toUpperCase().padStart(digits, '0');

class Cia402Drive extends EventEmitter {
    // node: 1..127. tauMs: the position loop's time constant. playCounts: the
    // cable play (backlash) between motor and cable end. initialCounts: where
    // motor and cable end stand at power-up. targetWindowCounts: how near the
    // target the statusword says "target reached".
    constructor({ node, tauMs = 2, playCounts = 0, initialCounts = 0, targetWindowCounts = 10 } = {}) {
        super();
        if (!Number.isInteger(node) || node < 1 || node > 127)
            throw new RangeError('node id must be in 1..127');
        if (!(tauMs >= 0) || !(playCounts >= 0) || !Number.isFinite(initialCounts))
            throw new RangeError('tau and play must be >= 0, the initial position finite');

        this.node = node;
        this.tauMs = tauMs;
        this.playCounts = playCounts;
        this.targetWindowCounts = targetWindowCounts;

        // The physics, which no reset touches.
        this.motorCounts = initialCounts;
        this.cableCounts = initialCounts;
        this.heldTarget = initialCounts;  // where quick stop holds

        this.power = PowerState.SWITCH_ON_DISABLED;
        this.lastControlword = 0;

        // Injected faults.
        this.silent = false;
        this.heartbeatStopped = false;
        this.duplicateTpdos = false;
        this.lateSyncs = 0;          // SYNCs whose TPDOs are still to be held back
        this.heldTpdos = [];         // held back, sent after the next SYNC

        this.pendingReset = null;    // 'node' | 'communication' while the stack resets
        this.applicationSnapshot = null;
        this.syncReleased = null;    // frames the stack sends while it handles a SYNC

        this.device = new Device({ id: node, eds: this._buildDictionary(), enableLss: false });
        this.eds = this.device.eds;
        this._applyCommunicationDefaults();
        this._applyApplicationDefaults();
        this._publishState();

        // The stack's SYNC module produces SYNCs, which a drive never does,
        // yet runs an idle timer every 0x1006 period while it is started: a
        // wake-up each millisecond per drive. The PDO module reads the SYNC
        // on its own, so the SYNC module is stopped whenever it starts.
        this.device.sync.on('start', () => this.device.sync.stop());
        this.device.on('message', (frame) => this._fromStack(frame));
        this.device.nmt.on('changeState', (state) => this._nmtChanged(state));
        this.eds.getEntry(0x6060).on('update', () => this._mirrorMode());
        this.previousNmt = this.device.nmt.state;
    }

    // ---- public ----

    start() {
        this.device.start();
    }

    stop() {
        this.device.stop();
    }

    get nmtState() {
        return this.device.nmt.state;
    }

    get statusword() {
        return this.eds.getEntry(0x6041).value;
    }

    get positionCounts() {
        return this.eds.getEntry(0x6064).value;
    }

    // One frame from the bus: { id, data: Buffer }.
    receive({ id, data }) {
        if (this.silent) return;
        data = Buffer.from(data);

        if (id === NMT_ID) {
            this._noteNmtCommand(data);
            this.device.receive({ id, data });
            return;
        }
        if (id === this._syncCobId()) {
            this._onSync(id, data);
            return;
        }
        if (id === this._sdoRequestCobId()) {
            this._onSdoRequest(id, data);
            return;
        }
        const rpdo = this.device.pdo.started ? this.device.pdo.receiveMap[id] : undefined;
        if (rpdo && data.length < rpdo.dataSize) {
            // CiA 301: an RPDO shorter than its mapping is not processed (the
            // stack would copy the objects that fit).
            this._event(`RPDO ${hex(id, 3)} of ${data.length} bytes ignored: ${rpdo.dataSize} mapped`);
            return;
        }
        this.device.receive({ id, data });
    }

    // ---- injectable faults ----

    stopHeartbeat() {
        this.heartbeatStopped = true;
        this._event('fault injected: heartbeat stopped');
    }

    resumeHeartbeat() {
        this.heartbeatStopped = false;
    }

    // An EMCY with this error code and error register 0x01 (generic), and
    // the CiA 402 fault.
    emergency(code) {
        this.eds.getEntry(0x1001).value = 0x01;
        this._event(`fault injected: EMCY ${hex(code, 4)}`);
        this._sendEmergency(code);
        this._enter(PowerState.FAULT);
        this._publishState();
    }

    // Every SDO download to this object is refused (read only); a reset does
    // not lift it.
    refuseWrite(index) {
        const entry = this.eds.getEntry(index);
        if (!entry) throw new RangeError(`no object ${hex(index, 4)}`);
        if (entry.subNumber > 0) {
            for (let sub = 0; sub <= 0xFF; ++sub)
                if (entry.at(sub)) entry.at(sub).accessType = AccessType.READ_ONLY;
        } else {
            entry.accessType = AccessType.READ_ONLY;
        }
        this._event(`fault injected: writes to ${hex(index, 4)} refused`);
    }

    // Nothing in, nothing out: the drive that never answers.
    setSilent(on = true) {
        this.silent = on;
        if (on) this._event('fault injected: silent');
    }

    // The TPDOs of the next n SYNCs are held back and each sent after the
    // following SYNC, before that SYNC's own: the manager sees none, then two.
    lateTpdo(n = 1) {
        this.lateSyncs = n;
        this._event(`fault injected: TPDOs of the next ${n} SYNC(s) late`);
    }

    twiceTpdo(on = true) {
        this.duplicateTpdos = on;
        if (on) this._event('fault injected: every TPDO twice');
    }

    // ---- the object dictionary ----

    _buildDictionary() {
        const node = this.node;
        const eds = new Eds({ productName: 'cdcr simulated CiA 402 drive' });
        // Defaults live in this.defaults (index, sub, value), applied at every
        // reset: the stack's own reset skips RECORD sub-objects.
        this.defaults = [];
        const variable = (index, name, dataType, accessType, value, pdoMapping = false) => {
            eds.addEntry(index, { parameterName: name, objectType: ObjectType.VAR, dataType, accessType,
                defaultValue: value, pdoMapping });
            this.defaults.push([index, null, value]);
        };
        const record = (index, name, subs) => {
            const entry = eds.addEntry(index, { parameterName: name, objectType: ObjectType.RECORD });
            for (const [sub, subName, dataType, accessType, value] of subs) {
                entry.addSubObject(sub, { parameterName: subName, dataType, accessType, defaultValue: value });
                this.defaults.push([index, sub, value]);
            }
            return entry;
        };
        const { UNSIGNED8: U8, UNSIGNED16: U16, UNSIGNED32: U32, INTEGER8: I8, INTEGER32: I32 } = DataType;
        const { READ_WRITE: RW, READ_ONLY: RO } = AccessType;

        // 0x1000, 0x1001 and 0x1018 come with the Eds; the device type is ours.
        const deviceType = eds.getEntry(0x1000);
        deviceType.defaultValue = DEVICE_TYPE_SERVO;
        this.defaults.push([0x1000, null, DEVICE_TYPE_SERVO]);

        variable(0x1005, 'COB-ID SYNC', U32, RW, 0x80);
        variable(0x1006, 'Communication cycle period', U32, RW, 0);
        variable(0x1007, 'Synchronous window length', U32, RW, 0);
        variable(0x1014, 'COB-ID EMCY', U32, RW, 0x80 + node);
        variable(0x1017, 'Producer heartbeat time', U16, RW, 0);  // off until the master asks
        record(0x1200, 'SDO server parameter', [
            [1, 'COB-ID client to server', U32, RO, 0x600 + node],
            [2, 'COB-ID server to client', U32, RO, 0x580 + node],
        ]);

        // The default mapping is not the manager's: its remapping must work.
        record(0x1400, 'RPDO1 communication parameter', [
            [1, 'COB-ID used by RPDO', U32, RW, 0x200 + node],
            [2, 'transmission type', U8, RW, 0xFF],
        ]);
        record(0x1800, 'TPDO1 communication parameter', [
            [1, 'COB-ID used by TPDO', U32, RW, 0x180 + node],
            [2, 'transmission type', U8, RW, 0xFF],
            [3, 'inhibit time', U16, RW, 0],
            [5, 'event timer', U16, RW, 0],
            [6, 'SYNC start value', U8, RW, 0],
        ]);
        const mappingSubs = (first) => {
            const subs = [];
            for (let sub = 1; sub <= MAPPING_ENTRIES; ++sub)
                subs.push([sub, `mapped object ${sub}`, U32, RW, sub === 1 ? first : 0]);
            return subs;
        };
        const rpdoMap = record(0x1600, 'RPDO1 mapping parameter', mappingSubs(0x60400010));
        const tpdoMap = record(0x1A00, 'TPDO1 mapping parameter', mappingSubs(0x60410010));
        for (const [map, index] of [[rpdoMap, 0x1600], [tpdoMap, 0x1A00]]) {
            map.at(0).defaultValue = 1;
            this.defaults.push([index, 0, 1]);
        }

        variable(0x6040, 'Controlword', U16, RW, 0, true);
        variable(0x6041, 'Statusword', U16, RO, STATUSWORD[PowerState.SWITCH_ON_DISABLED], true);
        variable(0x6060, 'Modes of operation', I8, RW, 0, true);
        variable(0x6061, 'Modes of operation display', I8, RO, 0, true);
        variable(0x6064, 'Position actual value', I32, RO, 0, true);
        variable(0x607A, 'Target position', I32, RW, 0, true);
        return eds;
    }

    _setDefault(index, sub, value) {
        const entry = this.eds.getEntry(index);
        const target = sub === null ? entry : entry.at(sub);
        target.value = value;
    }

    _applyCommunicationDefaults() {
        for (const [index, sub, value] of this.defaults)
            if (index < 0x2000) this._setDefault(index, sub, value);
        this.eds.getEntry(0x1001).value = 0;
    }

    _applyApplicationDefaults() {
        for (const [index, sub, value] of this.defaults)
            if (index >= 0x2000) this._setDefault(index, sub, value);
        this.eds.getEntry(0x607A).value = Math.round(this.cableCounts);
    }

    // The application objects a communication reset must leave alone.
    _snapshotApplication() {
        const snapshot = {};
        // Copies: the stack's RPDO writes into the objects' buffers in place.
        for (const index of [0x6040, 0x6060, 0x607A]) snapshot[index] = Buffer.from(this.eds.getEntry(index).raw);
        return snapshot;
    }

    _restoreApplication(snapshot) {
        for (const [index, raw] of Object.entries(snapshot)) this.eds.getEntry(Number(index)).raw = raw;
    }

    _mirrorMode() {
        this.eds.getEntry(0x6061).value = this.eds.getEntry(0x6060).value;
    }

    _syncCobId() {
        return this.eds.getEntry(0x1005).value & 0x7FF;
    }

    _sdoRequestCobId() {
        return this.eds.getEntry(0x1200).at(1).value & 0x7FF;
    }

    _sdoReplyCobId() {
        return this.eds.getEntry(0x1200).at(2).value & 0x7FF;
    }

    // ---- NMT ----

    _noteNmtCommand(data) {
        if (data.length < 2 || (data[1] !== 0 && data[1] !== this.node)) return;
        const command = data[0];
        if (command === NMT_RESET_NODE || command === NMT_RESET_COMMUNICATION) {
            // The stack resets the dictionary synchronously and restarts on
            // the next turn of the event loop; what the drive keeps is taken now.
            this.pendingReset = command === NMT_RESET_NODE ? 'node' : 'communication';
            this.applicationSnapshot = this._snapshotApplication();
            this.heldTpdos = [];
            this.lateSyncs = 0;
        } else if (command === NMT_START) {
            this.emit('nmtStart');
        }
    }

    _nmtChanged(state) {
        const previous = this.previousNmt;
        this.previousNmt = state;
        this._event(`NMT ${nmtName(previous)} -> ${nmtName(state)}`);
        if (previous === NmtState.INITIALIZING && state === NmtState.PRE_OPERATIONAL) this._booted();
    }

    // Initialisation is over: the dictionary holds its reset values; put
    // back what outlives the reset, then say so with the boot-up message.
    _booted() {
        const reset = this.pendingReset;
        this.pendingReset = null;
        if (reset) {
            this._applyCommunicationDefaults();
            if (reset === 'communication') {
                this._restoreApplication(this.applicationSnapshot);
            } else {
                this._applyApplicationDefaults();
                this.lastControlword = 0;
                this._enter(PowerState.SWITCH_ON_DISABLED);
            }
            this._mirrorMode();
            // A CiA 402 fault outlives a communication reset, and so does its error register.
            if (this.power === PowerState.FAULT) this.eds.getEntry(0x1001).value = 0x01;
        }
        this._publishState();
        this._transmit({ id: BOOT_UP_BASE + this.node, data: Buffer.from([0x00]) });
        this._event(reset ? `boot-up after reset ${reset}` : 'boot-up');
    }

    // ---- SDO ----

    // Checks before the stack's SDO server sees an expedited download; a
    // download to the PDO parameters is wrapped in a stop and start of the
    // PDO module so it maps the PDOs anew (CiA 301 dynamic mapping).
    _onSdoRequest(id, data) {
        const server = this.device.sdoServer;
        const isExpeditedDownload = data.length === 8 && (data[0] >> 5) === 1 && (data[0] & 0x02) !== 0;
        if (!server.started || !isExpeditedDownload) {
            this.device.receive({ id, data });
            return;
        }
        const index = data.readUInt16LE(1);
        const sub = data[3];
        const entry = this.eds.getEntry(index);
        const object = entry === undefined ? undefined : (entry.subNumber > 0 ? entry.at(sub) : entry);
        if (!object || object.accessType === AccessType.READ_ONLY || object.accessType === AccessType.CONSTANT) {
            this.device.receive({ id, data });  // the stack's own abort
            return;
        }

        const expectedSize = object.raw.length;
        const sizeIndicated = (data[0] & 0x01) !== 0;
        if (sizeIndicated && 4 - ((data[0] >> 2) & 0x3) !== expectedSize) {
            this._sdoAbort(index, sub, ABORT_LENGTH_MISMATCH);
            return;
        }
        if (!sizeIndicated) {
            // Size unstated: the object's own; the stack would take all four bytes.
            data = Buffer.from(data);
            data[0] = 0x23 | ((4 - expectedSize) << 2);
        }
        const payload = data.subarray(4, 4 + expectedSize);

        const refusal = this._checkDownload(index, sub, payload);
        if (refusal) {
            this._sdoAbort(index, sub, refusal);
            return;
        }
        const remaps = index >= PDO_PARAMETER_FIRST && index <= PDO_PARAMETER_LAST && this.device.pdo.started;
        if (remaps) this.device.pdo.stop();
        this.device.receive({ id, data });
        if (remaps) this.device.pdo.start();
    }

    // An abort code for a download the drive refuses, 0 to take it.
    _checkDownload(index, sub, payload) {
        if (index === 0x6060 && payload.readInt8(0) !== MODE_CSP) return ABORT_VALUE_RANGE;
        const isMapping = (index >= 0x1600 && index <= 0x17FF) || (index >= 0x1A00 && index <= 0x1BFF);
        if (!isMapping) return 0;
        const map = this.eds.getEntry(index);
        if (sub === 0) {
            const count = payload[0];
            if (count > MAPPING_ENTRIES) return ABORT_MAP_LENGTH;
            let bits = 0;
            for (let i = 1; i <= count; ++i) bits += map.at(i).value & 0xFF;
            return bits > 64 ? ABORT_MAP_LENGTH : 0;
        }
        const value = payload.readUInt32LE(0);
        if (value === 0) return 0;
        const mappedIndex = value >>> 16;
        const mappedSub = (value >>> 8) & 0xFF;
        const bits = value & 0xFF;
        const mapped = this.eds.getEntry(mappedIndex);
        const target = mapped === undefined ? undefined : (mapped.subNumber > 0 ? mapped.at(mappedSub) : mapped);
        if (!target || !target.pdoMapping || (mapped.subNumber === undefined && mappedSub !== 0)) return ABORT_NOT_MAPPABLE;
        if (bits !== 8 * target.raw.length) return ABORT_NOT_MAPPABLE;
        // An RPDO maps what the drive receives, a TPDO what it reports.
        const isReceive = index < 0x1A00;
        if (isReceive && target.accessType === AccessType.READ_ONLY) return ABORT_NOT_MAPPABLE;
        return 0;
    }

    _sdoAbort(index, sub, code) {
        const data = Buffer.alloc(8);
        data[0] = SDO_ABORT;
        data.writeUInt16LE(index, 1);
        data[3] = sub;
        data.writeUInt32LE(code >>> 0, 4);
        this._transmit({ id: this._sdoReplyCobId(), data });
    }

    // ---- SYNC: the drive's cycle ----

    _onSync(id, data) {
        const operational = this.device.nmt.state === NmtState.OPERATIONAL;
        if (operational) {
            // An RPDO writes the objects' buffers without an update event.
            this._mirrorMode();
            this._applyControlword(this.eds.getEntry(0x6040).value);
            this._moveOneCycle();
            this._publishState();
        }
        // The stack sends the TPDOs this SYNC releases, now with the values
        // just computed; they are caught to be sent, held or doubled.
        this.syncReleased = [];
        try {
            this.device.receive({ id, data });
        } finally {
            const released = this.syncReleased;
            this.syncReleased = null;
            this._releaseTpdos(released);
        }
    }

    _releaseTpdos(released) {
        const late = this.heldTpdos;
        this.heldTpdos = [];
        for (const frame of late) this._transmit(frame);
        if (released.length === 0) return;
        if (this.lateSyncs > 0) {
            --this.lateSyncs;
            this.heldTpdos = released;
            return;
        }
        for (const frame of released) {
            this._transmit(frame);
            if (this.duplicateTpdos) this._transmit(frame);
        }
    }

    _applyControlword(cw) {
        const faultResetEdge = (cw & CONTROL_FAULT_RESET) !== 0 && (this.lastControlword & CONTROL_FAULT_RESET) === 0;
        this.lastControlword = cw;
        const S = PowerState;
        switch (this.power) {
            case S.FAULT:
                if (faultResetEdge) {  // transition 15
                    this.eds.getEntry(0x1001).value = 0;
                    this._sendEmergency(0x0000);  // error reset
                    this._enter(S.SWITCH_ON_DISABLED);
                }
                break;
            case S.SWITCH_ON_DISABLED:
                if (isShutdown(cw)) this._enter(S.READY_TO_SWITCH_ON);  // 2
                break;
            case S.READY_TO_SWITCH_ON:
                if (isSwitchOn(cw)) {  // 3, and 4 when bit 3 asks for it too
                    this._enter(S.SWITCHED_ON);
                    if (isEnableOperation(cw)) this._enter(S.OPERATION_ENABLED);
                } else if (isDisableVoltage(cw) || isQuickStop(cw)) {
                    this._enter(S.SWITCH_ON_DISABLED);  // 7
                }
                break;
            case S.SWITCHED_ON:
                if (isEnableOperation(cw)) this._enter(S.OPERATION_ENABLED);  // 4
                else if (isShutdown(cw)) this._enter(S.READY_TO_SWITCH_ON);  // 6
                else if (isDisableVoltage(cw) || isQuickStop(cw)) this._enter(S.SWITCH_ON_DISABLED);  // 10
                break;
            case S.OPERATION_ENABLED:
                if (isDisableOperation(cw)) this._enter(S.SWITCHED_ON);  // 5
                else if (isShutdown(cw)) this._enter(S.READY_TO_SWITCH_ON);  // 8
                else if (isDisableVoltage(cw)) this._enter(S.SWITCH_ON_DISABLED);  // 9
                else if (isQuickStop(cw)) this._enter(S.QUICK_STOP_ACTIVE);  // 11
                break;
            case S.QUICK_STOP_ACTIVE:
                // Quick stop option 6: stop and stay, holding, until told.
                if (isDisableVoltage(cw)) this._enter(S.SWITCH_ON_DISABLED);  // 12
                else if (isEnableOperation(cw)) this._enter(S.OPERATION_ENABLED);  // 16
                break;
        }
    }

    _enter(state) {
        if (state === this.power) return;
        const previous = this.power;
        this.power = state;
        // Torque comes on, or the drive stops: it holds where the motor is.
        this.heldTarget = this.motorCounts;
        this._event(`power ${previous} -> ${state}`);
    }

    // One SYNC period of the position loop, then the cable end through its play.
    _moveOneCycle() {
        let target;
        if (this.power === PowerState.OPERATION_ENABLED) {
            target = this.eds.getEntry(0x6060).value === MODE_CSP ? this.eds.getEntry(0x607A).value : this.heldTarget;
        } else if (this.power === PowerState.QUICK_STOP_ACTIVE) {
            target = this.heldTarget;
        } else {
            return;  // no torque: nothing moves
        }
        const periodUs = this.eds.getEntry(0x1006).value;
        const dtMs = periodUs > 0 ? periodUs / 1000 : 1;
        const gain = this.tauMs > 0 ? 1 - Math.exp(-dtMs / this.tauMs) : 1;
        this.motorCounts += (target - this.motorCounts) * gain;

        const halfPlay = this.playCounts / 2;
        if (this.motorCounts - this.cableCounts > halfPlay) this.cableCounts = this.motorCounts - halfPlay;
        else if (this.cableCounts - this.motorCounts > halfPlay) this.cableCounts = this.motorCounts + halfPlay;
    }

    // 0x6041 and 0x6064 from the state; 0x6064 is the cable end, as a
    // load-side encoder reads it, so the play shows on the bus.
    _publishState() {
        const actual = clampInt32(Math.round(this.cableCounts));
        let statusword = STATUSWORD[this.power];
        const holding = this.power === PowerState.OPERATION_ENABLED || this.power === PowerState.QUICK_STOP_ACTIVE;
        if (holding) {
            const target = this.power === PowerState.OPERATION_ENABLED && this.eds.getEntry(0x6060).value === MODE_CSP
                ? this.eds.getEntry(0x607A).value : Math.round(this.heldTarget);
            if (Math.abs(target - actual) <= this.targetWindowCounts) statusword |= STATUS_TARGET_REACHED;
        }
        this.eds.getEntry(0x6041).value = statusword;
        this.eds.getEntry(0x6064).value = actual;
    }

    // ---- frames out ----

    _sendEmergency(code) {
        try {
            this.device.emcy.write(code, Buffer.alloc(5));
        } catch (error) {
            // EMCY is not produced outside pre-operational and operational.
            this._event(`EMCY ${hex(code, 4)} not sent: ${error.message}`);
        }
    }

    _fromStack(frame) {
        // The stack answers an expedited upload of four bytes without the
        // size bit (0x42): valid, but every other size says its size.
        if (frame.id === this._sdoReplyCobId() && frame.data.length === 8 && frame.data[0] === 0x42)
            frame = { id: frame.id, data: Buffer.from([0x43, ...frame.data.subarray(1)]) };
        if (this.syncReleased) {
            this.syncReleased.push(frame);
            return;
        }
        const isHeartbeat = frame.id === BOOT_UP_BASE + this.node && frame.data.length === 1 && frame.data[0] !== 0;
        if (isHeartbeat && this.heartbeatStopped) return;
        this._transmit(frame);
    }

    _transmit({ id, data }) {
        if (this.silent) return;
        this.emit('frame', { id, data: Buffer.from(data) });
    }

    _event(text) {
        this.emit('event', text);
    }
}

function nmtName(state) {
    switch (state) {
        case NmtState.INITIALIZING: return 'initialising';
        case NmtState.PRE_OPERATIONAL: return 'pre-operational';
        case NmtState.OPERATIONAL: return 'operational';
        case NmtState.STOPPED: return 'stopped';
    }
    return String(state);
}

function clampInt32(value) {
    return Math.max(-2147483648, Math.min(2147483647, value));
}

module.exports = { Cia402Drive, PowerState, STATUSWORD };
