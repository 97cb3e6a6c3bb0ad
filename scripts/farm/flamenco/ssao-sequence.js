// SPDX-License-Identifier: MIT
// A Flamenco 3 job type: build/bin/ssao over a shot, one task per chunk of frames. Copy this file
// into the Manager's scripts/ folder (the file name is the job type's name). docs/farm.md.
//
// Every task runs `ssao INPUT --camera CAMERA -o OUTPUT --frames FRAMES --chunk-size N
// --chunk-index I [--radius R] [EXTRA]` (the whole list, its chunk by index);
// each frame is bit for bit what a serial run writes, whatever the chunks.

const JOB_TYPE = {
  label: "SSAO sequence",
  description: "Screen-space ambient occlusion of a rendered EXR sequence (build/bin/ssao)",
  settings: [
    {
      key: "ssao",
      type: "string",
      default: "ssao",
      description: "The ssao program on the Workers (a path, or a Flamenco variable such as {ssao})",
    },
    {
      key: "input",
      type: "string",
      subtype: "file_path",
      required: true,
      description: "Rendered frames, with a frame placeholder: shot/render.####.exr",
    },
    {
      key: "camera",
      type: "string",
      subtype: "file_path",
      required: true,
      description: "Camera file: one for every frame, or one per frame (render.####.camera.json)",
    },
    {
      key: "output",
      type: "string",
      subtype: "file_path",
      required: true,
      description: "Output frames, with a frame placeholder: shot/ao.####.exr",
    },
    {
      key: "frames",
      type: "string",
      required: true,
      eval: "f'{C.scene.frame_start}-{C.scene.frame_end}'",
      description: "Frames: '1001-1100', '1-99x2', '1,5,9-12'",
    },
    { key: "chunk_size", type: "int32", default: 10, description: "Frames per task" },
    {
      key: "radius",
      type: "float",
      default: 0,
      description: "AO radius in scene units; 0 takes the camera file's ao_distance",
    },
    {
      key: "extra_args",
      type: "string",
      default: "",
      description: "More ssao options, separated by spaces: --quality high --skip-existing",
    },
  ],
};

function compileJob(job) {
  const settings = job.settings;
  if (!(settings.chunk_size >= 1)) {
    throw `chunk_size must be at least 1, got ${settings.chunk_size}`;
  }
  if (!(settings.radius >= 0)) throw `radius must be 0 or more, got ${settings.radius}`;
  const extra = (settings.extra_args || "").split(" ").filter((arg) => arg.length > 0);
  for (const arg of extra) {
    if (arg === "--frames" || arg.startsWith("--chunk-")) {
      throw `extra_args: ${arg} is set by the job type (frames, chunk_size)`;
    }
  }
  const radius = settings.radius > 0 ? ["--radius", String(settings.radius)] : [];
  // Each task gets the whole frame list and its chunk's index (ssao cuts the list as
  // frameChunker does: in order, chunk_size frames each), so that it can compute the frames
  // before its chunk that the temporal filter averages in, without writing them.
  let index = 0;
  for (const chunk of frameChunker(settings.frames, settings.chunk_size)) {
    const task = author.Task(`ssao-${chunk}`, "misc");
    task.addCommand(
      author.Command("exec", {
        exe: settings.ssao,
        args: [settings.input, "--camera", settings.camera, "-o", settings.output, "--frames",
               settings.frames, "--chunk-size", String(settings.chunk_size), "--chunk-index",
               String(index)].concat(radius, extra),
      }),
    );
    job.addTask(task);
    index += 1;
  }
}
