// The player's geometry: a piece as a solid of unit cubes, and cells to and from action text
// (cells are 0-based on the wire, 1-based in the text an agent writes).
import * as THREE from "./three.min.js";

export const FACES = [
  [[1, 0, 0], [[1, 0, 0], [1, 1, 0], [1, 1, 1], [1, 0, 1]]],
  [[-1, 0, 0], [[0, 1, 0], [0, 0, 0], [0, 0, 1], [0, 1, 1]]],
  [[0, 1, 0], [[1, 1, 0], [0, 1, 0], [0, 1, 1], [1, 1, 1]]],
  [[0, -1, 0], [[0, 0, 0], [1, 0, 0], [1, 0, 1], [0, 0, 1]]],
  [[0, 0, 1], [[0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]]],
  [[0, 0, -1], [[0, 1, 0], [1, 1, 0], [1, 0, 0], [0, 0, 0]]],
];

// A solid of unit cubes: only the faces no other cell of the piece covers.
export function solid(cells) {
  const have = new Set(cells.map((c) => c.join(",")));
  const pos = [];
  const nor = [];
  for (const c of cells) {
    for (const [n, quad] of FACES) {
      if (have.has([c[0] + n[0], c[1] + n[1], c[2] + n[2]].join(","))) continue;
      for (const i of [0, 1, 2, 0, 2, 3]) {
        pos.push(c[0] + quad[i][0], c[1] + quad[i][1], c[2] + quad[i][2]);
        nor.push(...n);
      }
    }
  }
  const g = new THREE.BufferGeometry();
  g.setAttribute("position", new THREE.Float32BufferAttribute(pos, 3));
  g.setAttribute("normal", new THREE.Float32BufferAttribute(nor, 3));
  return g;
}

export function pieceObject(cells, rgb, opacity) {
  const geom = solid(cells);
  const mat = new THREE.MeshLambertMaterial({ color: new THREE.Color(rgb), transparent: opacity < 1, opacity });
  const mesh = new THREE.Mesh(geom, mat);
  const edges = new THREE.LineSegments(new THREE.EdgesGeometry(geom, 30), new THREE.LineBasicMaterial({ color: 0x222222 }));
  mesh.add(edges);
  return mesh;
}

export function cellsOf(text) {
  return [...text.matchAll(/\((-?\d+),(-?\d+),(-?\d+)\)/g)].map((m) => [+m[1] - 1, +m[2] - 1, +m[3] - 1]);
}

export function cellsText(cells) {
  const sorted = cells.map((c) => c.slice()).sort((a, b) => a[0] - b[0] || a[1] - b[1] || a[2] - b[2]);
  return sorted.map((c) => `(${c[0] + 1},${c[1] + 1},${c[2] + 1})`).join(" ");
}
