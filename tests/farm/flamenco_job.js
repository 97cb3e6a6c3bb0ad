// SPDX-License-Identifier: MIT
// Compiles scripts/farm/flamenco/ssao-sequence.js as a Flamenco Manager would and prints its
// tasks' commands as JSON, for tests/farm/test_flamenco.py (Flamenco is not in Debian):
//   node tests/farm/flamenco_job.js JOB_TYPE.js '{"input": ..., "frames": "1-11", ...}'
// The job type sees only what Flamenco gives it: author.Task, author.Command, frameChunker and
// print. frameChunker here follows Flamenco's documented behaviour: the frames cut into chunks
// of chunk_size, each written as its runs of consecutive frames ("1-3", "7,9-10").
"use strict";
const fs = require("fs");
const vm = require("vm");

function expandFrames(spec) {
  const frames = [];
  for (const part of spec.split(",")) {
    const match = /^\s*(-?\d+)\s*(?:-\s*(-?\d+))?\s*$/.exec(part);
    if (!match) throw new Error(`frameChunker: cannot read '${part}'`);
    const first = Number(match[1]);
    const last = match[2] === undefined ? first : Number(match[2]);
    for (let frame = first; frame <= last; ++frame) frames.push(frame);
  }
  return frames;
}

function runs(frames) {
  const parts = [];
  for (let i = 0; i < frames.length; ) {
    let end = i;
    while (end + 1 < frames.length && frames[end + 1] === frames[end] + 1) ++end;
    parts.push(end > i ? `${frames[i]}-${frames[end]}` : `${frames[i]}`);
    i = end + 1;
  }
  return parts.join(",");
}

function frameChunker(spec, size) {
  const frames = expandFrames(spec);
  const chunks = [];
  for (let i = 0; i < frames.length; i += size) chunks.push(runs(frames.slice(i, i + size)));
  return chunks;
}

const [jobTypePath, settingsJson] = process.argv.slice(2);
const tasks = [];
const context = {
  author: {
    Task: (name, type) => {
      const task = { name, type, commands: [], addCommand: (c) => task.commands.push(c) };
      return task;
    },
    Command: (type, parameters) => ({ type, parameters }),
  },
  frameChunker,
  print: (...args) => console.error(...args),
};
vm.createContext(context);
vm.runInContext(fs.readFileSync(jobTypePath, "utf8"), context, { filename: jobTypePath });
const jobType = vm.runInContext("JOB_TYPE", context);
const settings = {};
for (const setting of jobType.settings) {
  if (setting.default !== undefined) settings[setting.key] = setting.default;
}
Object.assign(settings, JSON.parse(settingsJson));
for (const setting of jobType.settings) {
  if (setting.required && settings[setting.key] === undefined) {
    throw new Error(`setting '${setting.key}' is required`);
  }
}
const job = { settings, addTask: (task) => tasks.push(task) };
try {
  vm.runInContext("compileJob", context)(job);
} catch (error) {
  console.error(`compileJob: ${error}`);
  process.exit(1);
}
console.log(JSON.stringify({
  label: jobType.label,
  tasks: tasks.map((t) => ({ name: t.name, type: t.type, commands: t.commands })),
}));
