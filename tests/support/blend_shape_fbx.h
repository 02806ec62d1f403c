// blend_shape_fbx.h — an ASCII FBX 7.4 blend-shape face for the tests that need a real FBX with
// morph targets (Assimp reads it; nothing here ships one): a quad (control points 0..3) with two
// BlendShapeChannels and no skin or joints, as a face exported on its own, and one take ("talk")
// animating both channels' DeformPercent with keys at different times:
//   smile: moves points 1 and 3 by (0, 0, 0.5) and (0, 0.25, 0); keyed 0, 1, 2 s at 0, 100, 0 %;
//   frown: moves point 0 by (-0.3, 0, 0); keyed 0, 0.5, 2 s at 50, -25, 50 %.
// Assimp 5.2.5 merges all channels' keys into one list per time (only the channels keyed then)
// and reports weight = DeformPercent / 100.
#pragma once
#include <string>

#include "fbx_text.h"

namespace ossa::test {

inline const std::string kBlendShapeFbx =
    fbx_ascii_head(
        "\t\tP: \"UnitScaleFactor\", \"double\", \"Number\", \"\",100\n\t\tP: \"TimeMode\", \"enum\", \"\", \"\",6\n") +
    R"(Objects:  {
	Geometry: 2000, "Geometry::face", "Mesh" {
		Vertices: *12 {
			a: 0,0,0,1,0,0,0,1,0,1,1,0
		}
		PolygonVertexIndex: *6 {
			a: 0,1,-3,1,3,-3
		}
		GeometryVersion: 124
		LayerElementNormal: 0 {
			Version: 101
			Name: ""
			MappingInformationType: "ByPolygonVertex"
			ReferenceInformationType: "Direct"
			Normals: *18 {
				a: 0,0,1,0,0,1,0,0,1,0,0,1,0,0,1,0,0,1
			}
		}
		Layer: 0 {
			Version: 100
			LayerElement:  {
				Type: "LayerElementNormal"
				TypedIndex: 0
			}
		}
	}
	Model: 1000, "Model::root", "LimbNode" {
		Version: 232
	}
	Model: 1001, "Model::face", "Mesh" {
		Version: 232
	}
	Geometry: 3000, "Geometry::smile", "Shape" {
		Version: 100
		Indexes: *2 {
			a: 1,3
		}
		Vertices: *6 {
			a: 0,0,0.5,0,0.25,0
		}
		Normals: *6 {
			a: 0,0,0,0,0,0
		}
	}
	Geometry: 3001, "Geometry::frown", "Shape" {
		Version: 100
		Indexes: *1 {
			a: 0
		}
		Vertices: *3 {
			a: -0.3,0,0
		}
		Normals: *3 {
			a: 0,0,0
		}
	}
	Deformer: 4000, "Deformer::blend", "BlendShape" {
		Version: 100
	}
	Deformer: 4001, "SubDeformer::smile", "BlendShapeChannel" {
		Version: 100
		DeformPercent: 0
		FullWeights: *1 {
			a: 100
		}
	}
	Deformer: 4002, "SubDeformer::frown", "BlendShapeChannel" {
		Version: 100
		DeformPercent: 0
		FullWeights: *1 {
			a: 100
		}
	}
	AnimationStack: 5000, "AnimStack::talk", "" {
		Properties70:  {
			P: "LocalStop", "KTime", "Time", "",92372316000
		}
	}
	AnimationLayer: 5001, "AnimLayer::BaseLayer", "" {
	}
	AnimationCurveNode: 5002, "AnimCurveNode::DeformPercent", "" {
		Properties70:  {
			P: "d|DeformPercent", "Number", "", "A",0
		}
	}
	AnimationCurve: 5003, "AnimCurve::", "" {
		Default: 0
		KeyVer: 4008
		KeyTime: *3 {
			a: 0,46186158000,92372316000
		}
		KeyValueFloat: *3 {
			a: 0,100,0
		}
		KeyAttrFlags: *1 {
			a: 24836
		}
		KeyAttrDataFloat: *4 {
			a: 0,0,218434821,0
		}
		KeyAttrRefCount: *1 {
			a: 3
		}
	}
	AnimationCurveNode: 5004, "AnimCurveNode::DeformPercent", "" {
		Properties70:  {
			P: "d|DeformPercent", "Number", "", "A",0
		}
	}
	AnimationCurve: 5005, "AnimCurve::", "" {
		Default: 0
		KeyVer: 4008
		KeyTime: *3 {
			a: 0,23093079000,92372316000
		}
		KeyValueFloat: *3 {
			a: 50,-25,50
		}
		KeyAttrFlags: *1 {
			a: 24836
		}
		KeyAttrDataFloat: *4 {
			a: 0,0,218434821,0
		}
		KeyAttrRefCount: *1 {
			a: 3
		}
	}
}
Connections:  {
	C: "OO",1000,0
	C: "OO",1001,1000
	C: "OO",2000,1001
	C: "OO",4000,2000
	C: "OO",4001,4000
	C: "OO",4002,4000
	C: "OO",3000,4001
	C: "OO",3001,4002
	C: "OO",5001,5000
	C: "OO",5002,5001
	C: "OO",5004,5001
	C: "OP",5002,4001, "DeformPercent"
	C: "OP",5003,5002, "d|DeformPercent"
	C: "OP",5004,4002, "DeformPercent"
	C: "OP",5005,5004, "d|DeformPercent"
}
)";

}  // namespace ossa::test
