#!/usr/bin/env node
// Runs the Khronos glTF validator (npm gltf-validator) on a glTF file, loading the files it
// references from its folder, prints the report's counts and messages, and exits 1 when the
// report has errors (warnings and infos are printed, not fatal).
// usage: node validate_gltf.js FILE.gltf
'use strict';
const fs = require('fs');
const path = require('path');
const validator = require('gltf-validator');

const file = process.argv[2];
const dir = path.dirname(file);
validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
    uri: path.basename(file),
    externalResourceFunction: (uri) =>
        new Promise((resolve, reject) => {
            fs.readFile(path.join(dir, decodeURIComponent(uri)), (err, data) => (err ? reject(err.toString()) : resolve(new Uint8Array(data))));
        }),
}).then((report) => {
    const i = report.issues;
    console.log(`${file}: ${i.numErrors} errors, ${i.numWarnings} warnings, ${i.numInfos} infos`);
    for (const m of i.messages)
        console.log(`  ${['error', 'warning', 'info', 'hint'][m.severity]} ${m.code} ${m.pointer || ''}: ${m.message}`);
    process.exit(i.numErrors === 0 ? 0 : 1);
}, (err) => {
    console.error(`${file}: validator failed: ${err}`);
    process.exit(1);
});
