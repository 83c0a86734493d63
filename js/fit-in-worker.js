// `geofit/worker`: a fit off the main thread without writing the worker. Each call starts a module
// worker (worker.js, found by `new URL(..., import.meta.url)`, which bundlers follow), sends it the
// file, forwards its frames to `onProgress` and its phases to `onPhase`, and resolves with the result; aborting `signal`
// terminates the worker at once, even in the middle of an iteration. Types: fit-in-worker.d.ts.

/** @type {import('./fit-in-worker.js').fitInWorker} */
export function fitInWorker(fileBytes, name, spec = {}, options = {}) {
  const { onProgress, onPhase, signal, sliceMs = 40, resolution = 3, exports = [] } = options;
  return new Promise((resolve, reject) => {
    if (signal?.aborted) {
      reject(signal.reason);
      return;
    }
    const worker = new Worker(new URL('./worker.js', import.meta.url), { type: 'module', name: 'geofit' });
    const finish = () => {
      worker.terminate();
      signal?.removeEventListener('abort', abort);
    };
    const abort = () => {
      finish();
      reject(signal?.reason);
    };
    signal?.addEventListener('abort', abort, { once: true });
    worker.onmessage = ({ data }) => {
      if (data.type === 'frame') {
        onProgress?.(data);
        return;
      }
      if (data.type === 'phase') {
        onPhase?.(data.phase, data.done);
        return;
      }
      finish();
      if (data.type === 'done') resolve(data.result);
      else reject(new Error(data.message));
    };
    worker.onerror = (event) => {
      finish();
      reject(new Error(`geofit worker failed to start: ${event.message || 'no message (is worker.js served?)'}`));
    };
    const bytes = fileBytes instanceof Uint8Array ? fileBytes : new Uint8Array(fileBytes);
    worker.postMessage({ bytes, name, spec, sliceMs, resolution, exports }, [bytes.buffer]);
  });
}
