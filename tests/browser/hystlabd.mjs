// Starting and stopping a hystlabd for the browser test and bench_page: the port comes from the
// line the daemon prints once it serves (it was started with --port 0, or a port it is given).
import { spawn } from 'node:child_process';

// Returns { proc, port }: port resolves to the daemon's port, or rejects with what it printed
// when it exits first or does not serve within timeoutMs. onOutput sees everything it prints.
export function startDaemon(daemonPath, args, { cwd, timeoutMs = 30000, onOutput = () => {} } = {}) {
  const proc = spawn(daemonPath, args, { cwd, stdio: ['ignore', 'pipe', 'pipe'] });
  let log = '';
  const port = new Promise((resolve, reject) => {
    const timer = setTimeout(() => reject(new Error(`hystlabd did not start within ${timeoutMs / 1000} s:\n` + log)), timeoutMs);
    const onData = d => {
      log += d;
      onOutput(String(d));
      const m = /serving the API and the page on http:\/\/127\.0\.0\.1:(\d+)\//.exec(log);
      if (m) { clearTimeout(timer); resolve(Number(m[1])); }
    };
    proc.stdout.on('data', onData);
    proc.stderr.on('data', onData);
    proc.on('exit', code => reject(new Error(`hystlabd exited (${code}):\n${log}`)));
  });
  return { proc, port };
}

// SIGTERM, then waits for the daemon to exit (at once if it already has).
export async function stopDaemon(proc) {
  if (proc.exitCode !== null) return;
  const exited = new Promise(r => proc.on('exit', r));
  proc.kill('SIGTERM');
  await exited;
}
