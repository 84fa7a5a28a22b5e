// Draws the rays of a reduced-resolution view (render::reduced) over the view: the
// premultiplied colours, bilinearly filtered from the smaller texture the ray caster
// drew into, blended "over" the meshes as the ray caster itself would.

#import bevy_core_pipeline::fullscreen_vertex_shader::FullscreenVertexOutput

@group(0) @binding(0) var drawn: texture_2d<f32>;
@group(0) @binding(1) var drawn_sampler: sampler;

@fragment
fn fragment(in: FullscreenVertexOutput) -> @location(0) vec4<f32> {
    return textureSampleLevel(drawn, drawn_sampler, in.uv, 0.0);
}
