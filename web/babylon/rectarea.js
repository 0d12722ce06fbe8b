// One RectAreaLight (Babylon.js 9, intensity 1, white) over a chart of 1-pixel PBRMaterial quads, nothing else lit: each
// pixel is Babylon's LTC area-light specular (ltcHelperFunctions: LTCUv, LTCEvaluate; computeAreaSpecularLighting) at
// its own shading point, normal, roughness and light polygon. No environment and material.environmentBRDFTexture null:
// no energy-conservation factor from the environment BRDF multiplies the light (what the test measures is the LTC
// tables). Babylon's camera looks down +z (left-handed); the chart lies at z = 0, quad (x, y) = [x, x + 1] x [y, y + 1]
// times `scale`, each quad's normal (0, sqrt(1 - NoV²), -NoV); the eye sits `eye` world units in front of the chart's
// centre (Babylon's view vector is normalize(eye - P) under an orthographic camera too), far, so v is nearly -z.
//
// The tables: Babylon creates scene._ltcTextures (Lights/areaLight.pure.js CreateSceneLTCTextures: two 64² RGBA
// HALF_FLOAT RawTextures, bilinear, clamp, invertY false) and fills them from areaLightsLTC.bin, fetched through
// Tools.GetAssetUrl: spec.assets (Tools.AssetBaseUrl) points Babylon at the folder of lutbake's file
// (<assets>/areaLights/areaLightsLTC.bin); none: Babylon's own CDN file (needs the network).
import { Engine } from '/web/node_modules/@babylonjs/core/Engines/engine.js';
import { Constants } from '/web/node_modules/@babylonjs/core/Engines/constants.js';
import '/web/node_modules/@babylonjs/core/Engines/Extensions/engine.rawTexture.js';
import '/web/node_modules/@babylonjs/core/Engines/Extensions/engine.renderTarget.js';
import '/web/node_modules/@babylonjs/core/Engines/Extensions/engine.readTexture.js';
import { Scene } from '/web/node_modules/@babylonjs/core/scene.js';
import { Camera } from '/web/node_modules/@babylonjs/core/Cameras/camera.js';
import { FreeCamera } from '/web/node_modules/@babylonjs/core/Cameras/freeCamera.js';
import { Quaternion, Vector3 } from '/web/node_modules/@babylonjs/core/Maths/math.vector.js';
import { Color3, Color4 } from '/web/node_modules/@babylonjs/core/Maths/math.color.js';
import { Mesh } from '/web/node_modules/@babylonjs/core/Meshes/mesh.js';
import { TransformNode } from '/web/node_modules/@babylonjs/core/Meshes/transformNode.js';
import { VertexData } from '/web/node_modules/@babylonjs/core/Meshes/mesh.vertexData.js';
import { PBRMaterial } from '/web/node_modules/@babylonjs/core/Materials/PBR/pbrMaterial.js';
import { Texture } from '/web/node_modules/@babylonjs/core/Materials/Textures/texture.js';
import { RenderTargetTexture } from '/web/node_modules/@babylonjs/core/Materials/Textures/renderTargetTexture.js';
import { RectAreaLight } from '/web/node_modules/@babylonjs/core/Lights/rectAreaLight.js';
import { Tools } from '/web/node_modules/@babylonjs/core/Misc/tools.js';
import { expose } from '/web/furnace.js';

const params = new URLSearchParams( location.search );
// the demo's light (the tests pass their own): three.js rectarea.js's, mirrored in z (Babylon's camera looks down +z)
const LIGHT = { position: [ 0.5, 1.1, - 0.9 ], xAxis: [ 1, 0, 0 ], yAxis: [ 0, - 0.8320502943, - 0.5547001962 ],
	width: 1.0, height: 0.6, intensity: 1 };
const SCALE = 1 / 32;
const EYE_DISTANCE = 1e4;
let engine = null;

const vec = ( a ) => new Vector3( ...a );

// light: { position, xAxis, yAxis (unit, orthogonal), width, height, intensity }: the light's local x and y in the
// world (a parent TransformNode rotates it; it emits along -(xAxis x yAxis)); its corners are position +- width/2
// xAxis +- height/2 yAxis
function areaLight( scene, light ) {

	const node = new TransformNode( 'rectParent', scene );
	node.position = vec( light.position );
	const z = Vector3.Cross( vec( light.xAxis ), vec( light.yAxis ) );
	node.rotationQuaternion = Quaternion.RotationQuaternionFromAxis( vec( light.xAxis ), vec( light.yAxis ), z );
	const rect = new RectAreaLight( 'rect', Vector3.Zero(), light.width, light.height, scene );
	rect.parent = node;
	rect.intensity = light.intensity;
	rect.diffuse = new Color3( 1, 1, 1 );
	rect.specular = new Color3( 1, 1, 1 );
	return rect;

}

// spec.assets: Tools.AssetBaseUrl ('' : Babylon's CDN); else spec.lut (the demo, ?lut=): 'shipped' (the CDN) or
// 'lutbake' (/lut/babylon: make demo puts lutbake's areaLightsLTC.bin in outputs/babylon/areaLights/)
async function rectArea( { nov, rows, light = LIGHT, scale = SCALE, eye = EYE_DISTANCE, lut = params.get( 'lut' ) || 'shipped',
	assets = lut === 'lutbake' ? '/lut/babylon' : '' } ) {

	const width = nov.length, height = rows.length;
	if ( ! engine ) {

		const canvas = document.createElement( 'canvas' );
		canvas.width = width;
		canvas.height = height;
		engine = new Engine( canvas, false, { preserveDrawingBuffer: true, stencil: false } );

	}
	engine.setSize( width, height );
	Tools.AssetBaseUrl = assets;
	const scene = new Scene( engine );
	scene.clearColor = new Color4( 0, 0, 0, 1 );
	scene.imageProcessingConfiguration.applyByPostProcess = true;  // no tone mapping, no gamma: linear float out

	const centre = new Vector3( width * scale / 2, height * scale / 2, 0 );
	const camera = new FreeCamera( 'camera', centre.add( new Vector3( 0, 0, - eye ) ), scene );
	camera.setTarget( centre );
	camera.mode = Camera.ORTHOGRAPHIC_CAMERA;
	camera.orthoLeft = - width * scale / 2;
	camera.orthoRight = width * scale / 2;
	camera.orthoBottom = - height * scale / 2;
	camera.orthoTop = height * scale / 2;
	camera.minZ = eye - 1;
	camera.maxZ = eye + 1;

	const meshes = rows.map( ( row, y ) => {

		const positions = [], normals = [], indices = [];
		nov.forEach( ( c, x ) => {

			const base = positions.length / 3;
			positions.push( x, y, 0, x + 1, y, 0, x + 1, y + 1, 0, x, y + 1, 0 );
			for ( let k = 0; k < 4; k ++ ) normals.push( 0, Math.sqrt( Math.max( 0, 1 - c * c ) ), - c );
			indices.push( base, base + 1, base + 2, base, base + 2, base + 3 );

		} );
		const mesh = new Mesh( `row${ y }`, scene );
		Object.assign( new VertexData(), { positions: positions.map( ( p ) => p * scale ), normals, indices } ).applyToMesh( mesh );
		const material = new PBRMaterial( `m${ y }`, scene );
		material.metallic = row.metalness;
		material.roughness = row.roughness;
		material.albedoColor = new Color3( ...row.color );
		material.environmentBRDFTexture = null;
		material.backFaceCulling = false;
		mesh.material = material;
		return mesh;

	} );
	const rect = areaLight( scene, light );

	const target = new RenderTargetTexture( 'rectarea', { width, height }, scene, false, true, Constants.TEXTURETYPE_FLOAT,
		false, Texture.NEAREST_SAMPLINGMODE );
	target.renderList = meshes;
	target.activeCamera = camera;
	target.clearColor = new Color4( 0, 0, 0, 1 );
	scene.customRenderTargets.push( target );
	scene.activeCamera = camera;
	await scene.whenReadyAsync();
	scene.render();
	const pixels = await target.readPixels();
	rect._computeTransformedInformation();
	const corners = { position: rect._pointTransformedPosition.asArray(), halfWidth: rect._pointTransformedWidth.scale( 0.5 ).asArray(),
		halfHeight: rect._pointTransformedHeight.scale( 0.5 ).asArray(), eye: camera.position.asArray() };
	const gl = engine._gl;
	return { width, height, pixels: new Float32Array( pixels.buffer, pixels.byteOffset, width * height * 4 ),
		canvas: engine.getRenderingCanvas(), renderer: gl.getParameter( gl.RENDERER ), info: corners, dispose: () => scene.dispose() };

}

expose( rectArea );
