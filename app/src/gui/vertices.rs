//! One frame of the 3D view as vertices: what the CPU builds ([`super::geometry`]) and the GPU
//! draws ([`super::render`]).

/// One vertex: position, normal (ignored by lines) and sRGB colour with alpha.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Vertex {
    /// World position.
    pub position: [f32; 3],
    /// Unit normal, for lighting.
    pub normal: [f32; 3],
    /// Colour, 0–255 per channel.
    pub color: [u8; 4],
}

/// Everything one frame of the view draws, built on the CPU.
#[derive(Clone, Debug, Default)]
pub struct Geometry {
    /// Opaque lit triangles, three vertices each.
    pub triangles: Vec<Vertex>,
    /// Lit triangles drawn see-through after everything else, without writing depth.
    pub transparent: Vec<Vertex>,
    /// Line segments, two vertices each.
    pub lines: Vec<Vertex>,
    /// Lit triangles drawn last, on a cleared depth buffer: in front of the body, so arrows inside
    /// or behind it stay visible (they still hide each other correctly).
    pub overlay_triangles: Vec<Vertex>,
    /// Line segments drawn with the overlay triangles.
    pub overlay_lines: Vec<Vertex>,
}
