// Runs hdrgen (the WebAssembly build radiantlab/HDRICalibrationTool ships,
// public/wasm/hdrgen.{js,wasm}) on a bracket with a response file that does
// not exist yet, so hdrgen derives the response itself and writes it.
// Called by hdrgen_rerun.sh, which extracts the module from the git snapshot.
//
//   node hdrgen_rerun.mjs WASM_DIR OUT.rsp [HDRGEN_FLAGS...] -- FILE...
import { readFileSync, writeFileSync } from "node:fs";
import path from "node:path";

const [wasmDir, out, ...rest] = process.argv.slice(2);
const sep = rest.indexOf("--");
if (!wasmDir || !out || sep < 0 || sep === rest.length - 1) {
  console.error("usage: node hdrgen_rerun.mjs WASM_DIR OUT.rsp [FLAGS...] -- FILE...");
  process.exit(2);
}
const flags = rest.slice(0, sep);
const files = rest.slice(sep + 1);
const factory = (await import(`file://${path.resolve(wasmDir, "hdrgen.js")}`)).default;
const binary = readFileSync(path.join(wasmDir, "hdrgen.wasm"));
const log = [];
const mod = await factory({
  // Built for the web: hand it the compiled module instead of letting it fetch.
  instantiateWasm(imports, done) {
    WebAssembly.instantiate(binary, imports).then((r) => done(r.instance, r.module));
    return {};
  },
  noInitialRun: true,
  print: (s) => log.push(s),
  printErr: (s) => log.push(s),
});
mod.FS.mkdir("/src");
mod.FS.mkdir("/work");
const staged = files.map((f) => {
  const name = `/src/${path.basename(f)}`;
  mod.FS.writeFile(name, readFileSync(f));
  return name;
});
try {
  mod.callMain(["-m", "1000", ...staged, "-o", "/work/out.hdr", "-r", "/work/out.rsp", ...flags, "-F"]);
} catch (e) {
  console.error(`hdrgen_rerun.mjs: hdrgen failed: ${String(e).slice(0, 300)}`);
  console.error(log.slice(-20).join("\n"));
  process.exit(1);
}
let rsp;
try {
  rsp = mod.FS.readFile("/work/out.rsp");
} catch {
  console.error("hdrgen_rerun.mjs: hdrgen wrote no response file");
  console.error(log.slice(-20).join("\n"));
  process.exit(1);
}
writeFileSync(out, rsp);
console.log(`wrote ${out}`);
