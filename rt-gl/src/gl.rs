//! The OpenGL 1.x–2.1 enumerants the recorder understands (values from
//! the OpenGL registry's `gl.xml`).

#![allow(missing_docs)]

pub const POINTS: u32 = 0x0000;
pub const LINES: u32 = 0x0001;
pub const LINE_LOOP: u32 = 0x0002;
pub const LINE_STRIP: u32 = 0x0003;
pub const TRIANGLES: u32 = 0x0004;
pub const TRIANGLE_STRIP: u32 = 0x0005;
pub const TRIANGLE_FAN: u32 = 0x0006;
pub const QUADS: u32 = 0x0007;
pub const QUAD_STRIP: u32 = 0x0008;
pub const POLYGON: u32 = 0x0009;

pub const COMPILE: u32 = 0x1300;
pub const COMPILE_AND_EXECUTE: u32 = 0x1301;

pub const MODELVIEW: u32 = 0x1700;
pub const PROJECTION: u32 = 0x1701;
pub const TEXTURE: u32 = 0x1702;

pub const COLOR_BUFFER_BIT: u32 = 0x0000_4000;
pub const DEPTH_BUFFER_BIT: u32 = 0x0000_0100;

pub const LIGHTING: u32 = 0x0B50;
pub const LIGHT0: u32 = 0x4000;
pub const NORMALIZE: u32 = 0x0BA1;
pub const RESCALE_NORMAL: u32 = 0x803A;
pub const COLOR_MATERIAL: u32 = 0x0B57;

pub const CW: u32 = 0x0900;
pub const FLAT: u32 = 0x1D00;
pub const SMOOTH: u32 = 0x1D01;

pub const AMBIENT: u32 = 0x1200;
pub const DIFFUSE: u32 = 0x1201;
pub const SPECULAR: u32 = 0x1202;
pub const POSITION: u32 = 0x1203;
pub const SPOT_DIRECTION: u32 = 0x1204;
pub const SPOT_EXPONENT: u32 = 0x1205;
pub const SPOT_CUTOFF: u32 = 0x1206;
pub const CONSTANT_ATTENUATION: u32 = 0x1207;
pub const LINEAR_ATTENUATION: u32 = 0x1208;
pub const QUADRATIC_ATTENUATION: u32 = 0x1209;
pub const EMISSION: u32 = 0x1600;
pub const SHININESS: u32 = 0x1601;
pub const AMBIENT_AND_DIFFUSE: u32 = 0x1602;

pub const LIGHT_MODEL_TWO_SIDE: u32 = 0x0B52;
pub const LIGHT_MODEL_AMBIENT: u32 = 0x0B53;

pub const FRONT: u32 = 0x0404;
pub const BACK: u32 = 0x0405;
pub const FRONT_AND_BACK: u32 = 0x0408;

pub const BYTE: u32 = 0x1400;
pub const UNSIGNED_BYTE: u32 = 0x1401;
pub const SHORT: u32 = 0x1402;
pub const UNSIGNED_SHORT: u32 = 0x1403;
pub const INT: u32 = 0x1404;
pub const UNSIGNED_INT: u32 = 0x1405;
pub const FLOAT: u32 = 0x1406;
pub const DOUBLE: u32 = 0x140A;

pub const RGBA: u32 = 0x1908;
pub const RGB: u32 = 0x1907;
pub const REPEAT: u32 = 0x2901;
pub const MODULATE: u32 = 0x2100;
pub const DECAL: u32 = 0x2101;
pub const REPLACE: u32 = 0x1E01;
pub const ADD: u32 = 0x0104;
/// `GL_BLEND` as a texture environment mode.
pub const BLEND_ENV: u32 = 0x0BE2;
pub const TEXTURE_ENV_MODE: u32 = 0x2200;
pub const TEXTURE_ENV_COLOR: u32 = 0x2201;
pub const TEXTURE_MAG_FILTER: u32 = 0x2800;
pub const TEXTURE_MIN_FILTER: u32 = 0x2801;
pub const TEXTURE_WRAP_S: u32 = 0x2802;
pub const TEXTURE_WRAP_T: u32 = 0x2803;
pub const NEAREST: u32 = 0x2600;
pub const NEVER: u32 = 0x0200;
pub const LESS: u32 = 0x0201;
pub const EQUAL: u32 = 0x0202;
pub const LEQUAL: u32 = 0x0203;
pub const NOTEQUAL: u32 = 0x0205;
pub const GEQUAL: u32 = 0x0206;
pub const ALWAYS: u32 = 0x0207;
pub const S: u32 = 0x2000;
pub const TEXTURE_GEN_MODE: u32 = 0x2500;
pub const OBJECT_PLANE: u32 = 0x2501;
pub const EYE_PLANE: u32 = 0x2502;
pub const EYE_LINEAR: u32 = 0x2400;
pub const OBJECT_LINEAR: u32 = 0x2401;
pub const SPHERE_MAP: u32 = 0x2402;
pub const BACK_BUFFER: u32 = 0x0405;
pub const VIEWPORT: u32 = 0x0BA2;

pub const ALL_ATTRIB_BITS: u32 = 0x000F_FFFF;
pub const CLIENT_ALL_ATTRIB_BITS: u32 = 0xFFFF_FFFF;
pub const DEPTH_TEST: u32 = 0x0B71;
pub const SCISSOR_TEST: u32 = 0x0C11;
pub const GREATER: u32 = 0x0204;
pub const POINT: u32 = 0x1B00;
pub const LINE: u32 = 0x1B01;
pub const FILL: u32 = 0x1B02;
pub const FOG_MODE: u32 = 0x0B65;
pub const FOG_DENSITY: u32 = 0x0B62;
pub const FOG_START: u32 = 0x0B63;
pub const FOG_END: u32 = 0x0B64;
pub const FOG_COLOR: u32 = 0x0B66;
pub const EXP: u32 = 0x0800;
pub const EXP2: u32 = 0x0801;
pub const LINEAR: u32 = 0x2601;
pub const SRC_ALPHA: u32 = 0x0302;
pub const ONE_MINUS_SRC_ALPHA: u32 = 0x0303;
pub const TEXTURE_2D: u32 = 0x0DE1;
pub const BLEND: u32 = 0x0BE2;
pub const FOG: u32 = 0x0B60;
pub const ALPHA_TEST: u32 = 0x0BC0;
pub const STENCIL_TEST: u32 = 0x0B90;
pub const CULL_FACE: u32 = 0x0B44;
pub const UNPACK_ALIGNMENT: u32 = 0x0CF5;
pub const PACK_ALIGNMENT: u32 = 0x0D05;
pub const UNPACK_ROW_LENGTH: u32 = 0x0CF2;
pub const PACK_ROW_LENGTH: u32 = 0x0D02;
pub const UNPACK_SKIP_ROWS: u32 = 0x0CF3;
pub const UNPACK_SKIP_PIXELS: u32 = 0x0CF4;
