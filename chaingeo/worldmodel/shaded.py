"""A small shaded rasteriser of our pieces, for testing the video judge on pictures unlike ours.

Video models draw pieces lit and shaded, with shadows, highlights, soft edges, noise,
compression and a camera that drifts; ``chain video`` draws them flat. This draws the same
posed parts (the iso camera, orthographic) with a depth buffer (exact at any pose, and a piece
pushed through another shows where their surfaces cross), a point light (diffuse and specular
terms vary across a face), a shadow map from the light onto the pieces and a ground plane,
then blur, noise and JPEG, with the camera shifted a little each frame. Everything random
comes from one seeded :class:`Look`; the label buffer (which part each pixel shows) is the
ground truth the corruption generator checks visibility with.
"""

from __future__ import annotations

import io
from dataclasses import dataclass
from typing import Final

import numpy as np
import numpy.typing as npt
from PIL import Image, ImageFilter

from chaingeo.core.arrays import F64, I32, U8
from chaingeo.kernels.jit import njit
from chaingeo.pictures.raster import FACE_CORNERS, NORMALS
from chaingeo.pictures.scene import CAMERAS

#: Supersampling per side (soft, anti-aliased edges once averaged down).
SUPER: Final = 2
#: Shadow map side (pixels) and depth bias (cells).
SHADOW_SIZE: Final = 384
SHADOW_BIAS: Final = 0.08


@dataclass(frozen=True)
class Part:
    """One rigid part in one frame: its ground-truth label (> 0), cells, colour and pose."""

    label: int
    cells: npt.NDArray[np.int64]
    rgb: tuple[float, float, float]
    rotation: F64
    translation: F64


@dataclass(frozen=True)
class Look:
    """Everything random about a shaded clip: size, light, material, ground, camera drift and
    the degradations applied to each frame."""

    width: int
    height: int
    light: F64  # unit vector toward the light
    ambient: float
    diffuse: float
    specular: float
    shininess: float
    ground: tuple[F64, F64]  # RGB 0-1 at the top and bottom of the picture
    shadow: float  # share of the light a shadow takes away
    blur: float  # Gaussian radius (output pixels)
    noise: float  # standard deviation (levels)
    quality: int  # JPEG quality
    drift: F64  # (frames, 3): x, y shift (share of width) and log-scale, per frame
    margin: float


def random_look(rng: np.random.Generator, frames: int) -> Look:
    """A seeded look for a clip of ``frames`` frames."""
    az, el = rng.uniform(0, 2 * np.pi), rng.uniform(np.radians(35), np.radians(70))
    light = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
    base = rng.uniform(0.25, 0.75)
    tint = rng.normal(0, 0.04, 3)
    top = np.clip(base + tint + rng.uniform(-0.1, 0.1), 0.05, 0.95)
    bottom = np.clip(top + rng.uniform(-0.15, 0.15), 0.05, 0.95)
    walk = np.cumsum(rng.normal(0, 1, (frames, 3)), axis=0)
    walk -= walk.mean(axis=0)
    span = np.abs(walk).max(axis=0) + 1e-9
    drift = walk / span * np.array([rng.uniform(0, 0.015), rng.uniform(0, 0.015), 0.01])
    w = int(rng.choice([320, 320, 288]))
    h = int(rng.choice([180, 240, w]))
    return Look(
        width=w,
        height=h,
        light=light,
        ambient=float(rng.uniform(0.25, 0.45)),
        diffuse=float(rng.uniform(0.5, 0.8)),
        specular=float(rng.uniform(0.1, 0.5)),
        shininess=float(rng.uniform(8, 40)),
        ground=(top, bottom),
        shadow=float(rng.uniform(0.3, 0.6)),
        blur=float(rng.uniform(0.0, 1.0)),
        noise=float(rng.uniform(0.5, 4.0)),
        quality=int(rng.integers(35, 90)),
        drift=drift,
        margin=float(rng.uniform(-0.12, 0.04)),
    )


def _outer_faces(
    part: Part,
) -> tuple[F64, F64]:
    """World corners (n, 4, 3) and unit normals (n, 3) of a part's faces not shared by two of
    its cells."""
    cells = np.asarray(part.cells, dtype=np.int64)
    own = {tuple(c) for c in cells.tolist()}
    corners, normals = [], []
    for f in range(6):
        dx, dy, dz = (int(v) for v in NORMALS[f])
        keep = [
            i for i, (x, y, z) in enumerate(cells.tolist()) if (x + dx, y + dy, z + dz) not in own
        ]
        if not keep:
            continue
        local = cells[keep][:, None, :] + FACE_CORNERS[f]
        corners.append(local @ part.rotation.T + part.translation)
        n = part.rotation @ NORMALS[f].astype(np.float64)
        normals.append(np.tile(n, (len(keep), 1)))
    if not corners:
        return np.zeros((0, 4, 3)), np.zeros((0, 3))
    return np.concatenate(corners), np.concatenate(normals)


@njit(cache=True)
def _raster_kernel(xy: F64, depth: F64, h: int, w: int, zbuf: F64, idbuf: I32) -> None:
    """Depth-buffered fill of quads (two triangles each): the nearest (largest depth) face's
    index at each pixel centre."""
    for f in range(xy.shape[0]):
        for tri in range(2):
            a, b, c = 0, 1 + tri, 2 + tri
            x0, y0, z0 = xy[f, a, 0], xy[f, a, 1], depth[f, a]
            x1, y1, z1 = xy[f, b, 0], xy[f, b, 1], depth[f, b]
            x2, y2, z2 = xy[f, c, 0], xy[f, c, 1], depth[f, c]
            den = (y1 - y2) * (x0 - x2) + (x2 - x1) * (y0 - y2)
            if abs(den) < 1e-12:
                continue
            lo_x = max(0, int(np.floor(min(x0, min(x1, x2)))))
            hi_x = min(w - 1, int(np.ceil(max(x0, max(x1, x2)))))
            lo_y = max(0, int(np.floor(min(y0, min(y1, y2)))))
            hi_y = min(h - 1, int(np.ceil(max(y0, max(y1, y2)))))
            for py in range(lo_y, hi_y + 1):
                cy = py + 0.5
                for px in range(lo_x, hi_x + 1):
                    cx = px + 0.5
                    l0 = ((y1 - y2) * (cx - x2) + (x2 - x1) * (cy - y2)) / den
                    l1 = ((y2 - y0) * (cx - x2) + (x0 - x2) * (cy - y2)) / den
                    l2 = 1.0 - l0 - l1
                    if l0 < -1e-9 or l1 < -1e-9 or l2 < -1e-9:
                        continue
                    z = l0 * z0 + l1 * z1 + l2 * z2
                    k = py * w + px
                    if z > zbuf[k]:
                        zbuf[k] = z
                        idbuf[k] = f


def _raster(xy: F64, depth: F64, h: int, w: int) -> tuple[F64, I32]:
    zbuf = np.full(h * w, -np.inf)
    idbuf = np.full(h * w, -1, dtype=np.int32)
    if len(xy):
        _raster_kernel(np.ascontiguousarray(xy), np.ascontiguousarray(depth), h, w, zbuf, idbuf)
    return zbuf.reshape(h, w), idbuf.reshape(h, w)


@njit(cache=True)
def _shade_kernel(
    zbuf: F64,
    idbuf: I32,
    front: npt.NDArray[np.int64],
    normals: F64,
    colors: F64,
    labels: I32,
    cam: F64,
    setup: F64,
    smap: F64,
    basis: F64,
    frame: F64,
    light_pos: F64,
    mat: F64,
    top: F64,
    bottom: F64,
    out: F64,
    lab: I32,
) -> None:
    """Per pixel: the world point seen (a face, or the ground plane), its shadow (3x3 samples
    of the light's depth map), and Blinn-Phong under a point light; the ground is a vertical
    gradient darkened in shadow."""
    h, w = zbuf.shape
    s, ox, oy, cx, cy, gz = setup[0], setup[1], setup[2], setup[3], setup[4], setup[5]
    amb, dif, spe, shin, sha, bias = mat[0], mat[1], mat[2], mat[3], mat[4], mat[5]
    n_s = smap.shape[0]
    p = np.empty(3)
    for y in range(h):
        for x in range(w):
            a = (x + 0.5 - ox) / s + cx
            b = -(y + 0.5 - oy) / s + cy
            f = idbuf[y, x]
            if f >= 0:
                d = zbuf[y, x]
            else:
                z0 = a * cam[0, 2] + b * cam[1, 2]
                d = (gz - z0) / cam[2, 2]
            for c in range(3):
                p[c] = a * cam[0, c] + b * cam[1, c] + d * cam[2, c]
            pu = p[0] * basis[0, 0] + p[1] * basis[0, 1] + p[2] * basis[0, 2]
            pv = p[0] * basis[1, 0] + p[1] * basis[1, 1] + p[2] * basis[1, 2]
            pl = p[0] * basis[2, 0] + p[1] * basis[2, 1] + p[2] * basis[2, 2]
            qx = int(np.floor((pu - frame[0]) * frame[2]))
            qy = int(np.floor((pv - frame[1]) * frame[2]))
            dark = 0.0
            for ddy in range(-1, 2):
                for ddx in range(-1, 2):
                    u, v = qx + ddx, qy + ddy
                    if 0 <= u < n_s and 0 <= v < n_s and smap[v, u] > pl + bias:
                        dark += 1.0 / 9.0
            lit = 1.0 - sha * dark
            if f < 0:
                t = (y + 0.5) / h
                g = 0.55 + 0.45 * lit
                for c in range(3):
                    out[y, x, c] = (top[c] * (1 - t) + bottom[c] * t) * g
                lab[y, x] = 0
                continue
            face = front[f]
            lx, ly, lz = light_pos[0] - p[0], light_pos[1] - p[1], light_pos[2] - p[2]
            ln = np.sqrt(lx * lx + ly * ly + lz * lz) + 1e-12
            lx, ly, lz = lx / ln, ly / ln, lz / ln
            nx, ny, nz = normals[face, 0], normals[face, 1], normals[face, 2]
            diff = max(0.0, nx * lx + ny * ly + nz * lz)
            hx, hy, hz = lx + cam[2, 0], ly + cam[2, 1], lz + cam[2, 2]
            hn = np.sqrt(hx * hx + hy * hy + hz * hz) + 1e-12
            sp = max(0.0, (nx * hx + ny * hy + nz * hz) / hn) ** shin
            for c in range(3):
                out[y, x, c] = colors[face, c] * (amb + dif * diff * lit) + spe * sp * lit
            lab[y, x] = labels[face]


class Shader:
    """Draws frames of one clip: the camera fitted once to the clip's world frame."""

    def __init__(self, frame: tuple[tuple[int, ...], tuple[int, ...]], look: Look) -> None:
        cam = CAMERAS["iso"]
        self.right, self.up, self.v = (np.array(x) for x in (cam.right, cam.up, cam.toward_viewer))
        self.look = look
        lo, hi = (np.array(c, dtype=np.float64) for c in frame)
        box = np.array(
            [[lo[i] if (k >> i) & 1 == 0 else hi[i] for i in range(3)] for k in range(8)]
        )
        sx, sy = box @ self.right, box @ self.up
        self.centre = np.array([(sx.min() + sx.max()) / 2, (sy.min() + sy.max()) / 2])
        fit = 1 - 2 * look.margin
        self.scale = min(look.width * fit / np.ptp(sx), look.height * fit / np.ptp(sy))
        self.ground_z = float(lo[2])
        self.light_pos = (lo + hi) / 2 + look.light * 2.5 * float(np.ptp(box, axis=0).max())

    def _screen(self, pts: F64, i: int) -> tuple[F64, F64]:
        """Supersampled pixel coordinates and depth of world points at frame ``i``."""
        dx, dy, ds = self.look.drift[min(i, len(self.look.drift) - 1)]
        s = self.scale * np.exp(ds) * SUPER
        w, h = self.look.width * SUPER, self.look.height * SUPER
        x = (pts @ self.right - self.centre[0]) * s + w / 2 + dx * w
        y = -(pts @ self.up - self.centre[1]) * s + h / 2 + dy * w
        return np.stack([x, y], axis=-1), pts @ self.v

    def _shadow_map(self, corners: F64, normals: F64) -> tuple[F64, F64, F64]:
        """Depth map along the light of the faces turned to it, and its frame: (lr, lu, light)
        rows and (lo_u, lo_v, pixels per cell)."""
        light = self.look.light
        lr = np.cross(np.array([0.0, 0.0, 1.0]), light)
        if np.linalg.norm(lr) < 1e-6:
            lr = np.array([1.0, 0.0, 0.0])
        lr /= np.linalg.norm(lr)
        lu = np.cross(light, lr)
        facing = normals @ light > 1e-9
        basis = np.stack([lr, lu, light])
        if not facing.any():
            return np.full((1, 1), -np.inf), basis, np.array([0.0, 0.0, 1.0])
        pts = corners[facing]
        u, v = pts @ lr, pts @ lu
        lo_u, lo_v = u.min() - 1, v.min() - 1
        k = (SHADOW_SIZE - 1) / max(u.max() + 1 - lo_u, v.max() + 1 - lo_v)
        xy = np.stack([(u - lo_u) * k, (v - lo_v) * k], axis=-1)
        zbuf, _ = _raster(xy, pts @ light, SHADOW_SIZE, SHADOW_SIZE)
        return zbuf, basis, np.array([lo_u, lo_v, k])

    def draw(self, parts: list[Part], i: int) -> tuple[F64, I32]:
        """Frame ``i`` as RGB in 0-1 at supersampled size, before degradations, and its label
        buffer (0: ground) at output size."""
        look = self.look
        faces = [_outer_faces(p) for p in parts]
        corners = np.concatenate([c for c, _ in faces]) if faces else np.zeros((0, 4, 3))
        normals = np.concatenate([n for _, n in faces]) if faces else np.zeros((0, 3))
        counts = [len(n) for _, n in faces]
        labels = np.repeat(np.array([p.label for p in parts], dtype=np.int32), counts)
        colors = np.repeat(
            np.array([p.rgb for p in parts], dtype=np.float64).reshape(-1, 3) / 255.0,
            counts,
            axis=0,
        )
        h, w = look.height * SUPER, look.width * SUPER
        front = np.flatnonzero(normals @ self.v > 1e-9)
        xy, dep = self._screen(corners[front], i)
        zbuf, idbuf = _raster(xy, dep, h, w)
        smap, basis, frame = self._shadow_map(corners, normals)
        dx, dy, ds = self.look.drift[min(i, len(self.look.drift) - 1)]
        s = self.scale * np.exp(ds) * SUPER
        cam = np.stack([self.right, self.up, self.v])
        setup = np.array(
            [s, w / 2 + dx * w, h / 2 + dy * w, self.centre[0], self.centre[1], self.ground_z]
        )
        mat = np.array(
            [look.ambient, look.diffuse, look.specular, look.shininess, look.shadow, SHADOW_BIAS]
        )
        out = np.empty((h, w, 3))
        lab = np.zeros((h, w), dtype=np.int32)
        _shade_kernel(
            zbuf, idbuf, front.astype(np.int64), normals, colors, labels, cam, setup,
            smap, basis, frame, self.light_pos, mat, look.ground[0], look.ground[1], out, lab,
        )  # fmt: skip
        return out, lab[SUPER // 2 :: SUPER, SUPER // 2 :: SUPER].copy()

    def finish(self, picture: F64, rng: np.random.Generator) -> U8:
        """Averaged down to output size, blurred, noised and JPEG-compressed."""
        look = self.look
        h, w = look.height, look.width
        small = picture.reshape(h, SUPER, w, SUPER, 3).mean(axis=(1, 3))
        img = Image.fromarray(np.clip(small * 255 + 0.5, 0, 255).astype(np.uint8))
        if look.blur > 0.05:
            img = img.filter(ImageFilter.GaussianBlur(look.blur))
        arr = np.asarray(img, dtype=np.float64) + rng.normal(0, look.noise, (h, w, 3))
        img = Image.fromarray(np.clip(arr + 0.5, 0, 255).astype(np.uint8))
        buf = io.BytesIO()
        img.save(buf, format="JPEG", quality=look.quality)
        buf.seek(0)
        with Image.open(buf) as back:
            return np.asarray(back.convert("RGB"), dtype=np.uint8)
