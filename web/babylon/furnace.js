// The white furnace, Babylon.js (PBRMaterial, metallic/roughness, the engine's defaults: height-correlated Smith, its
// multiscatter energy conservation) under a uniform environment of radiance 1: a float RawCubeTexture of ones, one
// level, bilinear, so every LOD the reflection block asks for reads 1 (no prefiltering to approximate); or, with
// spec.environment, a prefiltered cube (lutbake's DDS, or Babylon's own prefilter of a .hdr). One 1-pixel quad
// per (NoV, row); each quad's vertex normals are the one unit vector whose dot with the view direction at the pixel's
// centre (Babylon's viewDirectionW = normalize(vEyePosition - vPositionW), also under an orthographic camera) is that
// column's NoV. Float render target, image processing off (applyByPostProcess with no post-process: linear output).
// Babylon's modules one by one (its index.js pulls in ~3400 files: 10 s in headless Chromium); the engine extensions
// a raw cube texture, render targets and their readback need are imported for their side effects
import { Engine } from '/web/node_modules/@babylonjs/core/Engines/engine.js';
import { Constants } from '/web/node_modules/@babylonjs/core/Engines/constants.js';
import '/web/node_modules/@babylonjs/core/Engines/Extensions/engine.rawTexture.js';
import '/web/node_modules/@babylonjs/core/Engines/Extensions/engine.renderTarget.js';
import '/web/node_modules/@babylonjs/core/Engines/Extensions/engine.readTexture.js';
// BaseTexture.sphericalPolynomial, the environment's irradiance PBRMaterial reads (USESPHERICALFROMREFLECTIONMAP):
// without it the white metal rendered 0.7495 instead of 1
import '/web/node_modules/@babylonjs/core/Materials/Textures/baseTexture.polynomial.js';
import { Scene } from '/web/node_modules/@babylonjs/core/scene.js';
import { Camera } from '/web/node_modules/@babylonjs/core/Cameras/camera.js';
import { FreeCamera } from '/web/node_modules/@babylonjs/core/Cameras/freeCamera.js';
import { Vector3 } from '/web/node_modules/@babylonjs/core/Maths/math.vector.js';
import { Color3, Color4 } from '/web/node_modules/@babylonjs/core/Maths/math.color.js';
import { Mesh } from '/web/node_modules/@babylonjs/core/Meshes/mesh.js';
import { VertexData } from '/web/node_modules/@babylonjs/core/Meshes/mesh.vertexData.js';
import { PBRMaterial } from '/web/node_modules/@babylonjs/core/Materials/PBR/pbrMaterial.js';
import { Texture } from '/web/node_modules/@babylonjs/core/Materials/Textures/texture.js';
import { RawCubeTexture } from '/web/node_modules/@babylonjs/core/Materials/Textures/rawCubeTexture.js';
import { CubeTexture } from '/web/node_modules/@babylonjs/core/Materials/Textures/cubeTexture.js';
import '/web/node_modules/@babylonjs/core/Engines/Extensions/engine.cubeTexture.js';
import '/web/node_modules/@babylonjs/core/Engines/Extensions/engine.prefilteredCubeTexture.js';
import '/web/node_modules/@babylonjs/core/Engines/Extensions/engine.renderTargetCube.js';
import { HDRCubeTexture } from '/web/node_modules/@babylonjs/core/Materials/Textures/hdrCubeTexture.js';
import { RenderTargetTexture } from '/web/node_modules/@babylonjs/core/Materials/Textures/renderTargetTexture.js';
import { RGBDTextureTools } from '/web/node_modules/@babylonjs/core/Misc/rgbdTextureTools.js';
import { expose } from '/web/furnace.js';

const params = new URLSearchParams( location.search );
const LUT = params.get( 'lut' ) || 'shipped';
const LUT_URL = '/lut/babylon_environment_brdf.dds';
const EYE_DISTANCE = 16;

// lutbake's DDS (DX10 header, RGBA16F) with its texels rearranged: the file a wrong bake or a wrong writer would give
function rearranged( bytes, mistake ) {

	const view = new DataView( bytes.buffer );
	const height = view.getUint32( 12, true ), width = view.getUint32( 16, true );
	const offset = 128 + 20;  // magic + DDS_HEADER, DDS_HEADER_DXT10
	const src = new Uint16Array( bytes.buffer.slice( offset, offset + width * height * 8 ) );
	const dst = new Uint16Array( bytes.buffer, offset, width * height * 4 );
	for ( let y = 0; y < height; y ++ ) for ( let x = 0; x < width; x ++ ) for ( let c = 0; c < 4; c ++ ) {

		const at = ( y * width + x ) * 4;
		if ( mistake === 'swapRG' ) dst[ at + c ] = src[ at + ( c < 2 ? 1 - c : c ) ];
		else if ( mistake === 'transpose' ) dst[ at + c ] = src[ ( x * width + y ) * 4 + c ];

	}
	return bytes;

}

// lutbake's table as the README says to load it (invertY false, isRGBD false), or with one upload mistake: 'invertY'
// (Babylon's Texture default, true), 'rgbd' (isRGBD true and the RGBD expansion Babylon runs on its own PNG),
// 'swapRG', 'transpose' (the texels rearranged, through the same loader)
async function lutbakeTexture( scene, mistake ) {

	let buffer = null;
	if ( mistake === 'swapRG' || mistake === 'transpose' ) {

		buffer = rearranged( new Uint8Array( await ( await fetch( LUT_URL ) ).arrayBuffer() ), mistake );

	}
	const texture = await new Promise( ( resolve, reject ) => {

		const t = new Texture( LUT_URL, scene, {
			noMipmap: true, invertY: mistake === 'invertY', samplingMode: Texture.BILINEAR_SAMPLINGMODE,
			buffer, forcedExtension: '.dds', onLoad: () => resolve( t ), onError: ( m, e ) => reject( new Error( `${ m } ${ e }` ) ),
		} );

	} );
	texture.wrapU = texture.wrapV = Texture.CLAMP_ADDRESSMODE;
	texture.gammaSpace = false;
	if ( mistake === 'rgbd' ) {

		texture.isRGBD = true;
		RGBDTextureTools.ExpandRGBDTexture( texture );

	}
	return texture;

}

// a prefiltered environment cube as Babylon loads one (CubeTexture of a .dds with prefiltered true: gammaSpace false,
// createPrefilteredCubeTexture, lodGenerationScale = lodScale (Babylon's default 0.8), lodGenerationOffset 0)
async function prefilteredCube( scene, url, lodScale ) {

	return await new Promise( ( resolve, reject ) => {

		const t = new CubeTexture( url, scene, { prefiltered: true, forcedExtension: '.dds', lodScale, lodOffset: 0,
			createPolynomials: true, onLoad: () => resolve( t ), onError: ( m, e ) => reject( new Error( `${ m } ${ e }` ) ) } );

	} );

}

// Babylon's own prefilter of a lat-long Radiance .hdr: HDRCubeTexture (size² faces, mips, harmonics, linear) with
// prefilterOnLoad, i.e. HDRFiltering (GGX importance sampling, 4096 samples, mip m at alphaG = 2^(m / 0.8) / size);
// the scene's whenReadyAsync waits for the prefilter
function babylonPrefiltered( scene, url, size ) {

	return new HDRCubeTexture( url, scene, size, false, true, false, true );

}

let engine = null;

// rows: [{ roughness, metalness, color: [r, g, b] }], nov: [NoV per column]. Returns the RGBA float pixels, row 0 at
// the bottom (row i of the result is rows[i]).
// environment: null (radiance 1 everywhere), the URL of a prefiltered DDS cube (lodScale: its lodGenerationScale) or
// of a lat-long .hdr that Babylon prefilters itself into hdrSize² faces;
// mixIrradiance: PBRMaterial's brdf.mixIblRadianceWithIrradiance (Babylon's default true: the shader's radiance is
// mix(prefiltered radiance, SH irradiance, alphaG), pbrBlockReflection MIX_IBL_RADIANCE_WITH_IRRADIANCE)
async function furnace( { nov, rows, lut = LUT, mistake = 'none', anisotropy = 1, environment = null, lodScale = 0.8,
	mixIrradiance = true, hdrSize = 32 } ) {

	const width = nov.length, height = rows.length;
	if ( ! engine ) {

		const canvas = document.createElement( 'canvas' );
		canvas.width = width;
		canvas.height = height;
		engine = new Engine( canvas, false, { preserveDrawingBuffer: true, stencil: false } );

	}
	engine.setSize( width, height );
	const scene = new Scene( engine );
	scene.clearColor = new Color4( 0, 0, 0, 1 );
	scene.imageProcessingConfiguration.applyByPostProcess = true;  // no tone mapping, no gamma: linear float out

	const face = () => new Float32Array( 4 * 4 * 4 ).fill( 1 );
	const hdr = environment && environment.endsWith( '.hdr' );
	scene.environmentTexture = hdr ? babylonPrefiltered( scene, environment, hdrSize )
		: environment ? await prefilteredCube( scene, environment, lodScale ) : new RawCubeTexture( scene, [ face(), face(), face(), face(), face(), face() ], 4,
		Constants.TEXTUREFORMAT_RGBA, Constants.TEXTURETYPE_FLOAT, false, false, Texture.BILINEAR_SAMPLINGMODE );
	scene.environmentTexture.gammaSpace = false;

	// the environment BRDF: set before the materials (PBRMaterial takes scene.environmentBRDFTexture, or Babylon's own
	// from BRDFTextureTools.GetEnvironmentBRDFTexture, when it is made)
	if ( lut === 'lutbake' ) scene.environmentBRDFTexture = await lutbakeTexture( scene, mistake );

	const eye = new Vector3( width / 2, height / 2, - EYE_DISTANCE );
	const camera = new FreeCamera( 'camera', eye, scene );
	camera.setTarget( new Vector3( width / 2, height / 2, 0 ) );
	camera.mode = Camera.ORTHOGRAPHIC_CAMERA;
	camera.orthoLeft = - width / 2;
	camera.orthoRight = width / 2;
	camera.orthoBottom = - height / 2;
	camera.orthoTop = height / 2;
	camera.minZ = 1;
	camera.maxZ = 2 * EYE_DISTANCE;

	const meshes = rows.map( ( row, y ) => {

		const positions = [], normals = [], indices = [];
		nov.forEach( ( c, x ) => {

			// the view direction at the pixel's centre, and the unit normal at angle acos(c) from it (in the plane of
			// the view direction and world y)
			const v = [ eye.x - x - 0.5, eye.y - y - 0.5, eye.z ];
			const lv = Math.hypot( ...v );
			v.forEach( ( _, k ) => v[ k ] /= lv );
			const t = [ - v[ 1 ] * v[ 0 ], 1 - v[ 1 ] * v[ 1 ], - v[ 1 ] * v[ 2 ] ];
			const lt = Math.hypot( ...t );
			const s = Math.sqrt( Math.max( 0, 1 - c * c ) );
			const n = v.map( ( vk, k ) => c * vk + s * t[ k ] / lt );
			const base = positions.length / 3;
			positions.push( x, y, 0, x + 1, y, 0, x + 1, y + 1, 0, x, y + 1, 0 );
			for ( let k = 0; k < 4; k ++ ) normals.push( ...n );
			indices.push( base, base + 1, base + 2, base, base + 2, base + 3 );

		} );
		const mesh = new Mesh( `row${ y }`, scene );
		Object.assign( new VertexData(), { positions, normals, indices } ).applyToMesh( mesh );
		const material = new PBRMaterial( `m${ y }`, scene );
		material.metallic = row.metalness;
		material.roughness = row.roughness;
		material.albedoColor = new Color3( ...row.color );
		material.backFaceCulling = false;
		material.useRadianceOcclusion = false;
		material.useHorizonOcclusion = false;
		material.brdf.mixIblRadianceWithIrradiance = mixIrradiance;
		mesh.material = material;
		return mesh;

	} );

	// Babylon samples every Texture with anisotropicFilteringLevel 4 by default; this chart changes NoV by 8 texels of a
	// 256² table from one pixel to the next (and the helper pixels of a 1-pixel quad still more), where a 4x anisotropic
	// footprint averages texels along it. Level 1 (bilinear) for both tables: the furnace measures the table, and
	// ?anisotropy=4 (spec.anisotropy) shows Babylon's default sampler
	scene.environmentBRDFTexture.anisotropicFilteringLevel = anisotropy;

	const target = new RenderTargetTexture( 'furnace', { width, height }, scene, false, true, Constants.TEXTURETYPE_FLOAT,
		false, Texture.NEAREST_SAMPLINGMODE );
	target.renderList = meshes;
	target.activeCamera = camera;
	target.clearColor = new Color4( 0, 0, 0, 1 );
	scene.customRenderTargets.push( target );
	scene.activeCamera = camera;
	await scene.whenReadyAsync();
	scene.render();
	const pixels = await target.readPixels();
	const gl = engine._gl;
	return { width, height, pixels: new Float32Array( pixels.buffer, pixels.byteOffset, width * height * 4 ),
		canvas: engine.getRenderingCanvas(), renderer: gl.getParameter( gl.RENDERER ), dispose: () => scene.dispose() };

}

expose( furnace );
