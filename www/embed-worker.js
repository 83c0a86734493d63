// The worker of embed-example.html: fits the file it is sent with geofit and posts the limit
// surface after every slice of at most 100 ms, until the fit stops.
import init, { Fitter, loadFile } from '../pkg/geofit.js';

const ready = init();

onmessage = async ({ data: { bytes, name, options } }) => {
  await ready;
  try {
    const scan = loadFile(bytes, name);
    const fitter = new Fitter(scan, options);
    scan.free();
    let stats = fitter.stats();
    while (stats.status === 'running') {
      stats = fitter.run(100);
      const mesh = fitter.limitMesh(3);
      const { positions, normals, indices } = mesh;
      mesh.free();
      postMessage({ stats, positions, normals, indices }, [positions.buffer, normals.buffer, indices.buffer]);
    }
    fitter.free();
  } catch (e) {
    postMessage({ error: e.message });
  }
};
