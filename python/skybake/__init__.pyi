# Type stubs of the skybake module (skybake._core re-exported).
# Arrays: numpy.ndarray of the exact dtype named, C-contiguous.
from os import PathLike
from typing import Callable, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

__version__: str

Path = Union[str, PathLike[str]]
F32 = npt.NDArray[np.float32]
F64 = npt.NDArray[np.float64]
U32 = npt.NDArray[np.uint32]
Vec3 = Sequence[float]

class Error(RuntimeError):
    """The library's one-line error. message: what went wrong; where: the argument, field or file."""

    message: str
    where: str

# --- build facts, threads, progress, images -----------------------------------------

def version() -> str: ...
def build_has_cuda() -> bool: ...
def cuda_device_count() -> int: ...
def set_threads(count: int) -> None: ...
def threads() -> int: ...
def set_quiet(quiet: bool) -> None: ...

class Backend:
    name: str
    device: str
    """Where it runs: 'cpu', 'cuda' or 'opengl'."""
    summary: str
    methods: list[str]
    """Its methods, the default first."""
    closest_hit: bool
    """Whether it answers ray queries (bounces)."""
    available: bool
    problem: str

def backends() -> list[Backend]:
    """The registered visibility backends (embree, cuda, raster, brute), each probed: whether it can run here."""

class ProgressEvent:
    label: str
    done: int
    total: int
    seconds: float
    status: str
    finished: bool
    fraction: float

Progress = Optional[Callable[[ProgressEvent], None]]

def save_image(path: Path, rgb: F32, exposure_ev: float = 0.0, tone: str = "aces") -> None:
    """(H, W, 3) linear float32: .exr as is, .png tone-mapped ('aces', 'reinhard', 'clamp'). Atomic."""

def load_image(path: Path) -> F32:
    """An EXR, HDR or PNG file as linear (H, W, 3) float32."""

# --- meshes -----------------------------------------------------------------------

class Mesh:
    """A triangle mesh. Properties return copies; assign to change them."""

    def __init__(self, positions: F32, indices: U32, normals: Optional[F32] = None, colors: Optional[F32] = None) -> None:
        """positions (N, 3) float32, indices (M, 3) uint32, normals (N, 3), colors (N, 4) linear RGBA."""
    vertex_count: int
    triangle_count: int
    positions: F32
    normals: F32
    colors: F32
    indices: U32
    texcoords: list[F32]
    attribute_names: list[str]
    def attribute(self, name: str) -> F32:
        """(N,) float32 for one component, else (N, C)."""
    def set_attribute(self, name: str, values: F32) -> None: ...
    def compute_normals(self) -> None: ...
    def validate(self) -> None: ...
    def bounds(self) -> tuple[tuple[float, float, float], tuple[float, float, float]]: ...
    def copy(self) -> Mesh: ...

def load_mesh(path: Path) -> Mesh:
    """glTF, PLY, and OBJ, STL, OFF, FBX, ... through Assimp; normals computed when missing."""

def save_mesh(path: Path, mesh: Mesh, ascii: bool = False) -> None:
    """.glb or .ply. Atomic."""

class BakeFile:
    """A bake's mesh and its file: a glTF 2.0 input keeps its document, as `skybake ao` writes it."""
    def __init__(self, input: Path, output: Path) -> None: ...
    @property
    def mesh(self) -> Mesh: ...
    @property
    def has_document(self) -> bool: ...
    def save(self, path: Path, ascii: bool = False) -> None: ...

def generate_mesh(kind: str, triangles: int = 20000, seed: int = 1) -> Mesh:
    """'sphere', 'terrain', 'city', 'bowl', 'wall' or 'torus'. Deterministic."""

def procedural_kinds() -> list[str]: ...

# --- sphere rules and spherical harmonics ----------------------------------------------

class Rule:
    """A sphere rule: Σ_k w_k f(x_k) ≈ (1/4π) ∫ f dω."""

    def __init__(self, spec: str) -> None:
        """'lebedev:590', 'design:20', 'mc:1024', 'fibonacci:500', 'phong:A:N', optional '+rotate[=SEED]'."""
    spec: str
    kind: str
    precision: int
    rotate: bool
    size: int
    points: F64
    weights: F64
    def __len__(self) -> int: ...

def sh_count(order: int) -> int: ...
def sh_index(l: int, m: int) -> int: ...
def sh_eval(order: int, directions: F64) -> F64:
    """Real orthonormal SH at unit directions (N, 3) float64: (N, (order + 1)²)."""

# --- the sky ------------------------------------------------------------------------

class Atmosphere:
    name: str
    planet_radius_km: float
    top_radius_km: float
    ground_albedo: tuple[float, float, float]
    sun_irradiance: tuple[float, float, float]
    components: list[str]
    def validate(self) -> None: ...
    def to_json(self) -> str: ...
    @staticmethod
    def from_json(text: str) -> Atmosphere: ...
    def density_from_altitude(self, altitude_km: float) -> float: ...
    def altitude_from_density(self, density: float) -> float: ...

def atmosphere_preset(name: str, paper_r: float = 10000.0, paper_m: float = 10000.0) -> Atmosphere:
    """'earth', 'paper' or 'paper-dense'."""

def atmosphere_presets() -> list[str]: ...
def load_atmosphere(path: Path) -> Atmosphere: ...
def save_atmosphere(path: Path, atmosphere: Atmosphere) -> None: ...

class NeuralSky:
    topology: str
    weight_count: int
    inputs: str
    outputs: str
    weights: F32
    atmosphere: Atmosphere
    training: dict[str, float]
    aerosol_range: Optional[tuple[float, float]]
    aerosol: float
    def to_json(self) -> str: ...
    @staticmethod
    def from_json(text: str) -> NeuralSky: ...
    def save(self, path: Path) -> None: ...
    def export(self, language: str = "glsl", function_name: str = "skybake_sky") -> str:
        """'glsl', 'glsl-es' (GLSL ES 3.00, WebGL 2), 'hlsl', 'cuda' or 'c'."""

def load_neural_sky(path: Path) -> NeuralSky: ...

class Sky:
    """What computes the sky (reference or network) and where (cpu or cuda). Radiance per unit sun irradiance."""

    @staticmethod
    def reference(atmosphere: Atmosphere, method: str = "tables", device: str = "cpu") -> Sky: ...
    @staticmethod
    def network(network: NeuralSky, device: str = "cpu") -> Sky: ...
    method: str
    device: str
    is_network: bool
    atmosphere: Atmosphere
    def evaluate(self, samples: F32) -> F32:
        """(N, 4) float32 [cos_view_zenith, cos_view_sun, cos_sun_zenith, density] -> (N, 3) float32."""
    def render(
        self,
        width: int = 512,
        height: int = 512,
        view: str = "fisheye",
        altitude_km: float = 0.0,
        sun_elevation_deg: float = 30.0,
        sun_azimuth_deg: float = 0.0,
        fov_deg: float = 90.0,
        yaw_deg: float = 0.0,
        pitch_deg: float = 0.0,
        sun_disc: bool = True,
        progress: Progress = None,
    ) -> F32:
        """(H, W, 3) float32 linear radiance; view 'fisheye', 'panorama' or 'camera'."""

def draw_sky_samples(count: int, seed: int = 1) -> F32: ...
def train_sky(
    atmosphere: Atmosphere,
    topology: str = "shared:16x12",
    inputs: str = "horizon",
    outputs: Optional[str] = None,
    samples: int = 800000,
    adam_epochs: Optional[int] = None,
    lm_iterations: Optional[int] = None,
    seed: int = 1,
    brightness: str = "log",
    table_rule: str = "refined",
    steps: int = 64,
    device: str = "cpu",
    aerosol_range: Optional[tuple[float, float]] = None,
    hard_share: float = 0.0,
    flight_share: Optional[float] = None,
    multiple_term: str = "march",
    progress: Progress = None,
) -> NeuralSky: ...

# --- bakes --------------------------------------------------------------------------

class BakeResult:
    ao: F32
    shading: F32
    bent_normal: F32
    bits: Optional[U32]
    backend: str
    method: str
    rule: str
    directions: int
    rays: int
    seconds: float
    build_seconds: float
    trace_seconds: float
    ray_offset: float
    clamped_vertices: int

def bake_ao(
    mesh: Mesh,
    rule: str = "lebedev:590",
    backend: str = "",
    method: Optional[str] = None,
    resolution: int = 0,
    max_distance: float = ...,
    offset: float = 0.0,
    back_faces: str = "occlude",
    normalize: bool = False,
    store_bits: bool = False,
    progress: Progress = None,
    device: str = "auto",
) -> BakeResult:
    """AO, shading coefficient and bent normals per vertex, also stored on the mesh. GIL released."""

def render_preview(
    mesh: Mesh,
    values: F32,
    width: int = 960,
    height: int = 720,
    azimuth_deg: float = 35.0,
    elevation_deg: float = 30.0,
    fov_deg: float = 35.0,
    samples: int = 2,
) -> F32:
    """The mesh shaded by per-vertex values, (N,) or (N, 3) float32: linear (H, W, 3) float32."""

# --- precomputed radiance transfer ----------------------------------------------------

class Transfer:
    order: int
    coefficients: int
    channels: int
    kind: str
    model: str
    bounces: int
    rule: str
    vertex_count: int
    coeffs: F32
    shading: F32

def bake_transfer(
    mesh: Mesh,
    rule: str = "lebedev:590",
    order: int = 3,
    kind: str = "shadowed",
    model: str = "prt",
    bounces: int = 0,
    albedo: Optional[F32] = None,
    backend: str = "",
    method: Optional[str] = None,
    resolution: int = 0,
    max_distance: float = ...,
    progress: Progress = None,
    device: str = "auto",
) -> Transfer: ...

class ShLight:
    order: int
    coeffs: F32
    sun_direction: tuple[float, float, float]
    sun_irradiance: tuple[float, float, float]
    def to_json(self, source: str = "python", rule: str = "") -> str: ...

def sky_light(
    sky: Sky,
    sun_elevation_deg: float = 30.0,
    sun_azimuth_deg: float = 0.0,
    altitude_km: float = 0.0,
    sun: bool = True,
    order: int = 3,
    rule: str = "horizon:32x36",
) -> ShLight: ...
def constant_light(radiance: Vec3, order: int = 3) -> ShLight: ...
def equirect_light(rgb: F32, order: int = 3, rule: str = "lebedev:2030") -> ShLight: ...
def sun_direction(elevation_deg: float, azimuth_deg: float) -> tuple[float, float, float]: ...
def relight(
    transfer: Transfer, light: ShLight, albedo: F32, normals: Optional[F32] = None, sun_visible: Optional[F32] = None
) -> F32: ...
def sun_visibility(mesh: Mesh, direction: Vec3, backend: str = "embree") -> F32: ...
def save_prt(path: Path, mesh: Union[Mesh, BakeFile], transfer: Transfer, albedo: Optional[F32] = None) -> None: ...
def load_prt(path: Path) -> tuple[Mesh, Transfer, F32]: ...
def export_prt_glsl(order: int = 3, channels: int = 1, function_name: str = "skybake_prt", es: bool = False) -> str: ...
