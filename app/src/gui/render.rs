//! The GPU side of the 3D view: lit triangles and lines, depth-tested.
//!
//! In `prepare()` the scene is drawn into the renderer's own colour and depth textures; in
//! `paint()` that colour texture is drawn into egui's render pass with one full-screen triangle.
//! This works alike in the native window, in egui_kittest (whose pass has no depth attachment)
//! and in WebGL2.

use super::vertices::Vertex;
use eframe::egui_wgpu::{self, wgpu};
use glam::{Mat4, Vec3};

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Uniforms {
    view_projection: [[f32; 4]; 4],
    light: [f32; 4],
}

const SCENE_SHADER: &str = r#"
struct Uniforms { view_projection: mat4x4<f32>, light: vec4<f32> };
@group(0) @binding(0) var<uniform> u: Uniforms;
struct In { @location(0) position: vec3<f32>, @location(1) normal: vec3<f32>, @location(2) color: vec4<f32> };
struct Out { @builtin(position) clip: vec4<f32>, @location(0) normal: vec3<f32>, @location(1) color: vec4<f32> };
@vertex fn vs(v: In) -> Out {
    var o: Out;
    o.clip = u.view_projection * vec4<f32>(v.position, 1.0);
    o.normal = v.normal;
    o.color = v.color;
    return o;
}
// Two-sided diffuse light plus ambient: inverted tets show their faces too.
@fragment fn lit(i: Out) -> @location(0) vec4<f32> {
    let diffuse = abs(dot(normalize(i.normal), u.light.xyz));
    return vec4<f32>(i.color.rgb * (0.35 + 0.65 * diffuse), i.color.a);
}
@fragment fn flat(i: Out) -> @location(0) vec4<f32> { return i.color; }
"#;

const BLIT_SHADER: &str = r#"
@group(0) @binding(0) var image: texture_2d<f32>;
@group(0) @binding(1) var image_sampler: sampler;
struct Out { @builtin(position) clip: vec4<f32>, @location(0) uv: vec2<f32> };
@vertex fn vs(@builtin(vertex_index) i: u32) -> Out {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    var o: Out;
    o.clip = vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, 0.0, 1.0);
    o.uv = uv;
    return o;
}
@fragment fn fs(i: Out) -> @location(0) vec4<f32> { return textureSample(image, image_sampler, i.uv); }
"#;

const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// A vertex buffer that grows as needed.
struct VertexBuffer {
    buffer: wgpu::Buffer,
    capacity: u64,
    count: u32,
}

impl VertexBuffer {
    fn new(device: &wgpu::Device) -> Self {
        Self {
            buffer: vertex_buffer(device, 1024),
            capacity: 1024,
            count: 0,
        }
    }

    fn upload(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, vertices: &[Vertex]) {
        let bytes: &[u8] = bytemuck::cast_slice(vertices);
        if bytes.len() as u64 > self.capacity {
            self.capacity = (bytes.len() as u64).next_power_of_two();
            self.buffer = vertex_buffer(device, self.capacity);
        }
        if !bytes.is_empty() {
            queue.write_buffer(&self.buffer, 0, bytes);
        }
        self.count = vertices.len() as u32;
    }

    fn draw(&self, pass: &mut wgpu::RenderPass<'_>) {
        if self.count > 0 {
            pass.set_vertex_buffer(0, self.buffer.slice(..));
            pass.draw(0..self.count, 0..1);
        }
    }
}

fn vertex_buffer(device: &wgpu::Device, size: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("tetlab vertices"),
        size,
        usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// The colour and depth textures the scene is drawn into, and the bind group that samples them.
struct Target {
    size: [u32; 2],
    color: wgpu::TextureView,
    depth: wgpu::TextureView,
    blit: wgpu::BindGroup,
}

/// The renderer's GPU objects, kept in egui_wgpu's callback resources: pipelines shared by all
/// views, and per view (the main view, the comparison) its own uniforms, buffers and target, so
/// that two views drawn in one egui frame do not overwrite each other.
pub struct Renderer {
    opaque: wgpu::RenderPipeline,
    transparent: wgpu::RenderPipeline,
    lines: wgpu::RenderPipeline,
    blit: wgpu::RenderPipeline,
    blit_layout: wgpu::BindGroupLayout,
    uniform_layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
    views: Vec<ViewResources>,
}

/// What one view draws with.
struct ViewResources {
    /// The version of the geometry last uploaded ([`super::geometry::ViewGeometry::version`]).
    uploaded: Option<(u64, u64)>,
    uniforms: wgpu::Buffer,
    uniform_group: wgpu::BindGroup,
    target: Option<Target>,
    triangle_buffer: VertexBuffer,
    transparent_buffer: VertexBuffer,
    line_buffer: VertexBuffer,
    overlay_triangle_buffer: VertexBuffer,
    overlay_line_buffer: VertexBuffer,
}

impl ViewResources {
    fn new(device: &wgpu::Device, uniform_layout: &wgpu::BindGroupLayout) -> Self {
        let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("tetlab uniforms"),
            size: std::mem::size_of::<Uniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let uniform_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("tetlab uniforms"),
            layout: uniform_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: uniforms.as_entire_binding(),
            }],
        });
        ViewResources {
            uploaded: None,
            uniforms,
            uniform_group,
            target: None,
            triangle_buffer: VertexBuffer::new(device),
            transparent_buffer: VertexBuffer::new(device),
            line_buffer: VertexBuffer::new(device),
            overlay_triangle_buffer: VertexBuffer::new(device),
            overlay_line_buffer: VertexBuffer::new(device),
        }
    }
}

impl Renderer {
    /// Creates the renderer and stores it where the view's paint callbacks find it.
    pub fn install(render_state: &egui_wgpu::RenderState) {
        let renderer = Renderer::new(&render_state.device, render_state.target_format);
        render_state
            .renderer
            .write()
            .callback_resources
            .insert(renderer);
    }

    fn new(device: &wgpu::Device, target_format: wgpu::TextureFormat) -> Self {
        let scene_shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("tetlab scene"),
            source: wgpu::ShaderSource::Wgsl(SCENE_SHADER.into()),
        });
        let blit_shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("tetlab blit"),
            source: wgpu::ShaderSource::Wgsl(BLIT_SHADER.into()),
        });
        let uniform_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("tetlab uniforms"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let scene_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("tetlab scene"),
            bind_group_layouts: &[Some(&uniform_layout)],
            immediate_size: 0,
        });
        let vertex_layout = wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<Vertex>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Unorm8x4],
        };
        // Faces are pushed back a little in depth so that edges drawn on them are not hidden.
        let scene_pipeline =
            |label, topology: wgpu::PrimitiveTopology, fragment, blend, depth_write| {
                let bias = if topology == wgpu::PrimitiveTopology::TriangleList {
                    wgpu::DepthBiasState {
                        constant: 4,
                        slope_scale: 1.5,
                        clamp: 0.0,
                    }
                } else {
                    Default::default()
                };
                device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                    label: Some(label),
                    layout: Some(&scene_layout),
                    vertex: wgpu::VertexState {
                        module: &scene_shader,
                        entry_point: Some("vs"),
                        compilation_options: Default::default(),
                        buffers: &[Some(vertex_layout.clone())],
                    },
                    primitive: wgpu::PrimitiveState {
                        topology,
                        ..Default::default()
                    },
                    depth_stencil: Some(wgpu::DepthStencilState {
                        format: DEPTH_FORMAT,
                        depth_write_enabled: Some(depth_write),
                        depth_compare: Some(wgpu::CompareFunction::LessEqual),
                        stencil: Default::default(),
                        bias,
                    }),
                    multisample: Default::default(),
                    fragment: Some(wgpu::FragmentState {
                        module: &scene_shader,
                        entry_point: Some(fragment),
                        compilation_options: Default::default(),
                        targets: &[Some(wgpu::ColorTargetState {
                            format: COLOR_FORMAT,
                            blend,
                            write_mask: wgpu::ColorWrites::ALL,
                        })],
                    }),
                    multiview_mask: None,
                    cache: None,
                })
            };
        let triangles = wgpu::PrimitiveTopology::TriangleList;
        let opaque = scene_pipeline("tetlab opaque", triangles, "lit", None, true);
        let transparent = scene_pipeline(
            "tetlab see-through",
            triangles,
            "lit",
            Some(wgpu::BlendState::ALPHA_BLENDING),
            false,
        );
        let lines = scene_pipeline(
            "tetlab lines",
            wgpu::PrimitiveTopology::LineList,
            "flat",
            None,
            true,
        );

        let blit_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("tetlab blit"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
            ],
        });
        let blit_pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("tetlab blit"),
            bind_group_layouts: &[Some(&blit_layout)],
            immediate_size: 0,
        });
        let blit = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("tetlab blit"),
            layout: Some(&blit_pipeline_layout),
            vertex: wgpu::VertexState {
                module: &blit_shader,
                entry_point: Some("vs"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: Default::default(),
            depth_stencil: None,
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &blit_shader,
                entry_point: Some("fs"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: target_format,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("tetlab blit"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        Renderer {
            opaque,
            transparent,
            lines,
            blit,
            blit_layout,
            uniform_layout,
            sampler,
            views: Vec::new(),
        }
    }

    /// The resources of view `view`, made on first use.
    fn view(&mut self, device: &wgpu::Device, view: usize) -> &mut ViewResources {
        while self.views.len() <= view {
            let resources = ViewResources::new(device, &self.uniform_layout);
            self.views.push(resources);
        }
        &mut self.views[view]
    }

    /// Makes view `view`'s target `size` pixels large if it is not.
    fn resize(&mut self, device: &wgpu::Device, view: usize, size: [u32; 2]) {
        if self.views[view]
            .target
            .as_ref()
            .is_none_or(|t| t.size != size)
        {
            let texture = |label, format, usage| {
                device
                    .create_texture(&wgpu::TextureDescriptor {
                        label: Some(label),
                        size: wgpu::Extent3d {
                            width: size[0],
                            height: size[1],
                            depth_or_array_layers: 1,
                        },
                        mip_level_count: 1,
                        sample_count: 1,
                        dimension: wgpu::TextureDimension::D2,
                        format,
                        usage,
                        view_formats: &[],
                    })
                    .create_view(&Default::default())
            };
            let color = texture(
                "tetlab view colour",
                COLOR_FORMAT,
                wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            );
            let depth = texture(
                "tetlab view depth",
                DEPTH_FORMAT,
                wgpu::TextureUsages::RENDER_ATTACHMENT,
            );
            let blit = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("tetlab blit"),
                layout: &self.blit_layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: wgpu::BindingResource::TextureView(&color),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: wgpu::BindingResource::Sampler(&self.sampler),
                    },
                ],
            });
            self.views[view].target = Some(Target {
                size,
                color,
                depth,
                blit,
            });
        }
    }
}

/// One frame of a 3D view: what to draw and from where.
pub struct ViewCallback {
    /// Which view: 0 the main one, 1 the comparison.
    pub view: usize,
    /// The geometry, kept by the view between frames; uploaded when its version is not the one
    /// the GPU holds.
    pub geometry: std::sync::Arc<std::sync::Mutex<super::geometry::ViewGeometry>>,
    /// World to clip space.
    pub view_projection: Mat4,
    /// Direction toward the light, unit length.
    pub light: Vec3,
    /// The view's size in points.
    pub size_points: [f32; 2],
    /// Background colour, linear 0–1 RGBA.
    pub background: [f64; 4],
}

impl egui_wgpu::CallbackTrait for ViewCallback {
    fn prepare(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        screen: &egui_wgpu::ScreenDescriptor,
        encoder: &mut wgpu::CommandEncoder,
        resources: &mut egui_wgpu::CallbackResources,
    ) -> Vec<wgpu::CommandBuffer> {
        let Some(renderer) = resources.get_mut::<Renderer>() else {
            return Vec::new();
        };
        let size = [
            ((self.size_points[0] * screen.pixels_per_point).round() as u32).max(1),
            ((self.size_points[1] * screen.pixels_per_point).round() as u32).max(1),
        ];
        let uniforms = Uniforms {
            view_projection: self.view_projection.to_cols_array_2d(),
            light: self.light.extend(0.0).to_array(),
        };
        let resources = renderer.view(device, self.view);
        queue.write_buffer(&resources.uniforms, 0, bytemuck::bytes_of(&uniforms));
        let view = self.geometry.lock().unwrap_or_else(|e| e.into_inner());
        if resources.uploaded != Some(view.version()) {
            let geometry = view.geometry();
            for (buffer, vertices) in [
                (&mut resources.triangle_buffer, &geometry.triangles),
                (&mut resources.transparent_buffer, &geometry.transparent),
                (&mut resources.line_buffer, &geometry.lines),
                (
                    &mut resources.overlay_triangle_buffer,
                    &geometry.overlay_triangles,
                ),
                (&mut resources.overlay_line_buffer, &geometry.overlay_lines),
            ] {
                buffer.upload(device, queue, vertices);
            }
            resources.uploaded = Some(view.version());
        }
        drop(view);
        renderer.resize(device, self.view, size);
        let renderer = &*renderer;
        let resources = &renderer.views[self.view];
        let target = resources.target.as_ref().expect("made above");
        let [r, g, b, a] = self.background;
        let background = wgpu::LoadOp::Clear(wgpu::Color { r, g, b, a });
        // The scene, then the overlay over it on a fresh depth buffer.
        for (load, passes) in [
            (
                background,
                [
                    (&renderer.opaque, &resources.triangle_buffer),
                    (&renderer.lines, &resources.line_buffer),
                    (&renderer.transparent, &resources.transparent_buffer),
                ]
                .as_slice(),
            ),
            (
                wgpu::LoadOp::Load,
                [
                    (&renderer.opaque, &resources.overlay_triangle_buffer),
                    (&renderer.lines, &resources.overlay_line_buffer),
                ]
                .as_slice(),
            ),
        ] {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("tetlab view"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &target.color,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load,
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &target.depth,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Discard,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_bind_group(0, &resources.uniform_group, &[]);
            for (pipeline, buffer) in passes {
                pass.set_pipeline(pipeline);
                buffer.draw(&mut pass);
            }
        }
        Vec::new()
    }

    fn paint(
        &self,
        _info: eframe::egui::PaintCallbackInfo,
        pass: &mut wgpu::RenderPass<'static>,
        resources: &egui_wgpu::CallbackResources,
    ) {
        let Some(renderer) = resources.get::<Renderer>() else {
            return;
        };
        let Some(target) = renderer
            .views
            .get(self.view)
            .and_then(|v| v.target.as_ref())
        else {
            return;
        };
        pass.set_pipeline(&renderer.blit);
        pass.set_bind_group(0, &target.blit, &[]);
        pass.draw(0..3, 0..1);
    }
}
