// Filament (npm `filament`: the WebAssembly build, WebGL2) renders a chart of 1-pixel quads through gltfio: a glTF
// (GLB) built here, one mesh per row of the chart, one metallic-roughness material per row, so the materials are
// gltfio's built-in ubershaders (no matc, no .filamat). Lit only by an image-based light Filament reads from a KTX 1
// file (Engine.createIblFromKtx1: the reflections cube) and the SH in that file's `sh` key, given to
// IndirectLight.Builder.irradianceSh(3, sh) (filament.js's createIblFromKtx1 only parses it into `shfloats`).
// Intensity 1, exposure 1 (Camera.setExposureDirect), post-processing off (no tone mapping, no dithering: the view
// writes the shader's linear output), an orthographic camera (Filament's view vector is then the camera's backward
// axis, +z, at every fragment), a float RenderTarget read back through gl.js.
//
// The chart: spec.nov (NoV per column: normals (0, sqrt(1 - NoV²), NoV)) or spec.normals (one unit normal per pixel,
// row 0 at the bottom), spec.rows (per row: { roughness, metalness, color }). spec.ibl: the KTX's URL (default: the
// furnace's, make demo writes it). spec.dfg: 'shipped' (Filament's built-in table), or the URL of a DDS (RGBA16F, rows
// as Filament uploads them) whose RGB is written into Filament's DFG texture in place of its own (gl.js), with
// spec.mistake 'none', 'flipY' or 'swapRG'; spec.lut (the demo, ?lut=): 'shipped', or 'lutbake' for lutbake's
// `filament-corrected` at the web build's 64² (make demo bakes it into outputs/filament-web/).
import { expose } from '/web/furnace.js';

const ready = new Promise( ( resolve ) => Filament.init( [], resolve ) );
const CAMERA_Z = 10;
const WEB = '/lut/filament-web';
const LUT = new URLSearchParams( location.search ).get( 'lut' ) || 'shipped';
let filament = null;

function setUp( width, height ) {

	const canvas = document.createElement( 'canvas' );
	canvas.width = width;
	canvas.height = height;
	const engine = Filament.Engine.create( canvas );
	const scene = engine.createScene();
	const renderer = engine.createRenderer();
	renderer.setClearOptions( { clearColor: [ 0, 0, 0, 1 ], clear: true } );
	const view = engine.createView();
	const camera = engine.createCamera( Filament.EntityManager.get().create() );
	camera.setExposureDirect( 1.0 );
	camera.setProjection( Filament.Camera$Projection.ORTHO, 0, width, 0, height, 1, 2 * CAMERA_Z );
	camera.lookAt( [ 0, 0, CAMERA_Z ], [ 0, 0, 0 ], [ 0, 1, 0 ] );
	view.setCamera( camera );
	view.setScene( scene );
	view.setViewport( [ 0, 0, width, height ] );
	view.setPostProcessingEnabled( false );
	const texture = ( format, usage ) => Filament.Texture.Builder().width( width ).height( height ).levels( 1 )
		.usage( usage ).format( format ).build( engine );
	const Format = Filament.Texture$InternalFormat;
	const target = Filament.RenderTarget.Builder()
		.texture( Filament.RenderTarget$AttachmentPoint.COLOR, texture( Format.RGBA32F, 1 | 16 ) )  // COLOR_ATTACHMENT | SAMPLEABLE
		.texture( Filament.RenderTarget$AttachmentPoint.DEPTH, texture( Format.DEPTH32F, 2 ) )  // DEPTH_ATTACHMENT
		.build( engine );
	view.setRenderTarget( target );
	return { canvas, engine, scene, renderer, view, swapChain: engine.createSwapChain(), loader: engine.createAssetLoader(),
		width, height, shippedDFG: null };

}

function chartNormals( { nov, normals, rows } ) {

	if ( normals ) return normals;
	const out = [];
	for ( let y = 0; y < rows.length; y ++ ) for ( const c of nov ) out.push( [ 0, Math.sqrt( Math.max( 0, 1 - c * c ) ), c ] );
	return out;

}

// The chart as a GLB: per row a mesh of 1-pixel quads at z = 0 (quad (x, y) = [x, x + 1] x [y, y + 1]), four vertices
// each with the pixel's normal, and its material
function chartGLB( spec, width, height ) {

	const normals = chartNormals( spec );
	const chunks = [], bufferViews = [], accessors = [], meshes = [], nodes = [], materials = [];
	let byteLength = 0;
	const addView = ( array, target ) => {

		chunks.push( array );
		bufferViews.push( { buffer: 0, byteOffset: byteLength, byteLength: array.byteLength, target } );
		byteLength += array.byteLength;
		return bufferViews.length - 1;

	};
	spec.rows.forEach( ( row, y ) => {

		const position = new Float32Array( width * 12 ), normal = new Float32Array( width * 12 );
		const index = new Uint32Array( width * 6 );
		for ( let x = 0; x < width; x ++ ) {

			position.set( [ x, y, 0, x + 1, y, 0, x + 1, y + 1, 0, x, y + 1, 0 ], 12 * x );
			for ( let k = 0; k < 4; k ++ ) normal.set( normals[ y * width + x ], 12 * x + 3 * k );
			index.set( [ 0, 1, 2, 0, 2, 3 ].map( ( i ) => 4 * x + i ), 6 * x );

		}
		const a = accessors.length;
		accessors.push(
			{ bufferView: addView( position, 34962 ), componentType: 5126, count: 4 * width, type: 'VEC3',
				min: [ 0, y, 0 ], max: [ width, y + 1, 0 ] },
			{ bufferView: addView( normal, 34962 ), componentType: 5126, count: 4 * width, type: 'VEC3' },
			{ bufferView: addView( index, 34963 ), componentType: 5125, count: 6 * width, type: 'SCALAR' } );
		materials.push( { pbrMetallicRoughness: { baseColorFactor: [ ...row.color, 1 ], metallicFactor: row.metalness,
			roughnessFactor: row.roughness } } );
		meshes.push( { primitives: [ { attributes: { POSITION: a, NORMAL: a + 1 }, indices: a + 2, material: y } ] } );
		nodes.push( { mesh: y } );

	} );
	const json = { asset: { version: '2.0' }, scene: 0, scenes: [ { nodes: nodes.map( ( _, i ) => i ) } ], nodes, meshes,
		materials, accessors, bufferViews, buffers: [ { byteLength } ] };
	const text = new TextEncoder().encode( JSON.stringify( json ) );
	const jsonLength = ( text.length + 3 ) & ~3, binLength = ( byteLength + 3 ) & ~3;
	const glb = new Uint8Array( 12 + 8 + jsonLength + 8 + binLength );
	const view = new DataView( glb.buffer );
	view.setUint32( 0, 0x46546C67, true );  // 'glTF'
	view.setUint32( 4, 2, true );
	view.setUint32( 8, glb.length, true );
	view.setUint32( 12, jsonLength, true );
	view.setUint32( 16, 0x4E4F534A, true );  // 'JSON'
	glb.fill( 0x20, 20, 20 + jsonLength );
	glb.set( text, 20 );
	view.setUint32( 20 + jsonLength, binLength, true );
	view.setUint32( 24 + jsonLength, 0x004E4942, true );  // 'BIN\0'
	let at = 28 + jsonLength;
	for ( const c of chunks ) {

		glb.set( new Uint8Array( c.buffer, c.byteOffset, c.byteLength ), at );
		at += c.byteLength;

	}
	return glb;

}

async function fetchBytes( url ) {

	const response = await fetch( url );
	if ( ! response.ok ) throw new Error( `${ url }: HTTP ${ response.status }` );
	return new Uint8Array( await response.arrayBuffer() );

}

// The RGB half-float bits of a DDS (DX10 header, RGBA16F), rows as stored, with an upload mistake
async function dfgBits( url, mistake, n ) {

	const bytes = await fetchBytes( url );
	const view = new DataView( bytes.buffer );
	const height = view.getUint32( 12, true ), width = view.getUint32( 16, true );
	if ( width !== n || height !== n ) throw new Error( `${ url }: ${ width }x${ height }, Filament's table is ${ n }²` );
	const rgba = new Uint16Array( bytes.buffer.slice( 148, 148 + n * n * 8 ) );  // magic + DDS_HEADER + DDS_HEADER_DXT10
	const bits = new Uint16Array( n * n * 3 );
	for ( let y = 0; y < n; y ++ ) for ( let x = 0; x < n; x ++ ) for ( let c = 0; c < 3; c ++ ) {

		const row = mistake === 'flipY' ? n - 1 - y : y;
		const channel = mistake === 'swapRG' && c < 2 ? 1 - c : c;
		bits[ ( y * n + x ) * 3 + c ] = rgba[ ( row * n + x ) * 4 + channel ];

	}
	return bits;

}

function loadAsset( state, glb ) {

	const asset = state.loader.createAsset( glb );
	return new Promise( ( resolve ) => asset.loadResources( () => resolve( asset ), null, null, null ) );

}

async function indirectLight( engine, url ) {

	const ktx = engine.createIblFromKtx1( await fetchBytes( url ) );
	if ( ! ktx.shfloats || ktx.shfloats.length !== 27 || ktx.shfloats.some( ( v ) => ! Number.isFinite( v ) ) ) {

		throw new Error( `${ url }: no 'sh' key of 27 numbers` );

	}
	const light = Filament.IndirectLight.Builder().reflections( ktx.getReflectionsTexture() )
		.irradianceSh( 3, ktx.shfloats ).intensity( 1.0 ).build( engine );
	return { light, sh: ktx.shfloats, levels: ktx.getReflectionsTexture().getLevels( engine ) };

}

function render( state ) {

	for ( let frame = 0; frame < 2; frame ++ ) {

		if ( state.renderer.beginFrame( state.swapChain ) ) {

			state.renderer.renderView( state.view );
			state.renderer.endFrame();

		}
		state.engine.execute();

	}
	return filamentGL.readFloat( state.engine.context, state.width, state.height );

}

async function furnace( spec ) {

	await ready;
	const width = spec.nov ? spec.nov.length : spec.width, height = spec.rows.length;
	if ( ! filament || filament.width !== width || filament.height !== height ) filament = setUp( width, height );
	const state = filament;
	const ibl = await indirectLight( state.engine, spec.ibl || `${ WEB }/filament_furnace_ibl.ktx` );
	state.scene.setIndirectLight( ibl.light );
	const asset = await loadAsset( state, chartGLB( spec, width, height ) );
	state.scene.addEntities( asset.getEntities() );
	render( state );  // the first frame uploads Filament's DFG texture (gl.js keeps its bits)
	if ( state.shippedDFG === null ) state.shippedDFG = filamentGL.dfg.slice();
	const lut = spec.lut || LUT;
	const dfg = spec.dfg || ( lut === 'lutbake' ? `${ WEB }/filament_dfg_corrected.dds` : 'shipped' );
	filamentGL.replaceDFG( dfg === 'shipped' ? state.shippedDFG : await dfgBits( dfg, spec.mistake || 'none', filamentGL.dfgSize ) );
	const pixels = render( state );
	filamentGL.replaceDFG( state.shippedDFG );
	state.scene.removeEntities( asset.getEntities() );
	state.loader.destroyAsset( asset );
	state.scene.setIndirectLight( null );
	state.engine.destroyIndirectLight( ibl.light );
	const gl = state.engine.context;
	return { width, height, pixels, canvas: state.canvas, renderer: gl.getParameter( gl.RENDERER ),
		info: { dfgSize: filamentGL.dfgSize, dfg: Array.from( state.shippedDFG ), sh: ibl.sh, levels: ibl.levels } };

}

expose( furnace );
