// The GUI protocol (docs/gui-protocol.md), generated from its table in the C++
// (src/gui/protocol_table.cc) by
//   saccade gui --protocol-js > web/public/app/protocol.js
// Do not edit: the test docs.gui_protocol_js fails when this file and the table differ. The
// checks are web/public/app/schema.js's, in the same words as the server's.
import { makeChecks } from './schema.js';

export const table = {
  "protocol": "saccade-gui",
  "version": 2,
  "types": {
    "pose": {
      "kind": "array",
      "items": [
        {"kind":"array","items":[{"kind":"number"}],"length":4},
        {"kind":"array","items":[{"kind":"number"}],"length":4},
        {"kind":"array","items":[{"kind":"number"}],"length":4},
        {
          "kind": "array",
          "items": [
            {"kind":"integer","const":0},
            {"kind":"integer","const":0},
            {"kind":"integer","const":0},
            {"kind":"integer","const":1}
          ],
          "length": 4
        }
      ],
      "length": 4
    },
    "point": {"kind":"array","items":[{"kind":"number"}],"length":3},
    "joints": {
      "kind": "object",
      "items": [{"kind":"number"}],
      "fields": [],
      "open": true,
      "others": "a joint (scene.head.joints)"
    },
    "rgb": {"kind":"array","items":[{"kind":"number"}],"length":3},
    "rgba": {"kind":"array","items":[{"kind":"number"}],"length":4},
    "effects": {
      "kind": "object",
      "fields": [
        {"name":"distortion","required":true,"schema":{"kind":"boolean"}},
        {"name":"noise","required":true,"schema":{"kind":"boolean"}},
        {"name":"motion_blur","required":true,"schema":{"kind":"boolean"}},
        {"name":"optics","required":true,"schema":{"kind":"boolean"}},
        {"name":"color","required":true,"schema":{"kind":"boolean"}}
      ]
    }
  },
  "messages": [
    {
      "type": "joints",
      "channel": "command",
      "body": {
        "kind": "object",
        "fields": [
          {"name":"type","required":true,"schema":{"kind":"string","const":"joints"}},
          {"name":"id","required":true,"schema":{"kind":"integer"}},
          {
            "name": "positions",
            "required": true,
            "schema": {
              "kind": "object",
              "items": [{"kind":"number"}],
              "fields": [{"name":"vergence","required":false,"schema":{"kind":"number"}}],
              "open": true,
              "others": "a joint (scene.head.joints)",
              "some": true
            }
          }
        ]
      },
      "reply": [
        {"name":"targets","required":true,"schema":{"ref":"joints"}},
        {"name":"perception","required":true,"schema":{"kind":"boolean","const":false}}
      ]
    },
    {
      "type": "fixate",
      "channel": "command",
      "body": {
        "kind": "object",
        "fields": [
          {"name":"type","required":true,"schema":{"kind":"string","const":"fixate"}},
          {"name":"id","required":true,"schema":{"kind":"integer"}},
          {"name":"p_W","required":true,"schema":{"ref":"point"}}
        ]
      },
      "reply": [
        {"name":"targets","required":true,"schema":{"ref":"joints"}},
        {"name":"axis_error_deg","required":true,"schema":{"kind":"number","min":0.0}},
        {"name":"perception","required":true,"schema":{"kind":"boolean","const":false}}
      ]
    },
    {
      "type": "perception",
      "channel": "command",
      "body": {
        "kind": "object",
        "fields": [
          {"name":"type","required":true,"schema":{"kind":"string","const":"perception"}},
          {"name":"id","required":true,"schema":{"kind":"integer"}},
          {"name":"enabled","required":false,"schema":{"kind":"boolean"}}
        ]
      },
      "reply": [{"name":"perception","required":true,"schema":{"kind":"boolean"}}]
    },
    {
      "type": "effects",
      "channel": "command",
      "body": {
        "kind": "object",
        "fields": [
          {"name":"type","required":true,"schema":{"kind":"string","const":"effects"}},
          {"name":"id","required":true,"schema":{"kind":"integer"}},
          {"name":"distortion","required":false,"schema":{"kind":"boolean"}},
          {"name":"noise","required":false,"schema":{"kind":"boolean"}},
          {"name":"motion_blur","required":false,"schema":{"kind":"boolean"}},
          {"name":"optics","required":false,"schema":{"kind":"boolean"}},
          {"name":"color","required":false,"schema":{"kind":"boolean"}}
        ]
      },
      "reply": [{"name":"effects","required":true,"schema":{"ref":"effects"}}]
    },
    {
      "type": "pause",
      "channel": "command",
      "body": {
        "kind": "object",
        "fields": [
          {"name":"type","required":true,"schema":{"kind":"string","const":"pause"}},
          {"name":"id","required":true,"schema":{"kind":"integer"}}
        ]
      },
      "reply": [{"name":"paused","required":true,"schema":{"kind":"boolean","const":true}}]
    },
    {
      "type": "resume",
      "channel": "command",
      "body": {
        "kind": "object",
        "fields": [
          {"name":"type","required":true,"schema":{"kind":"string","const":"resume"}},
          {"name":"id","required":true,"schema":{"kind":"integer"}}
        ]
      },
      "reply": [{"name":"paused","required":true,"schema":{"kind":"boolean","const":false}}]
    },
    {
      "type": "step",
      "channel": "command",
      "body": {
        "kind": "object",
        "fields": [
          {"name":"type","required":true,"schema":{"kind":"string","const":"step"}},
          {"name":"id","required":true,"schema":{"kind":"integer"}},
          {"name":"count","required":false,"schema":{"kind":"integer","min":1.0,"max":1000.0}}
        ]
      },
      "reply": [{"name":"steps","required":true,"schema":{"kind":"integer","min":1.0,"max":1000.0}}]
    },
    {
      "type": "record",
      "channel": "command",
      "body": {
        "kind": "object",
        "fields": [
          {"name":"type","required":true,"schema":{"kind":"string","const":"record"}},
          {"name":"id","required":true,"schema":{"kind":"integer"}},
          {"name":"enabled","required":true,"schema":{"kind":"boolean"}}
        ]
      },
      "reply": [{"name":"recording","required":true,"schema":{"kind":"boolean"}}]
    },
    {
      "type": "speed",
      "channel": "command",
      "body": {
        "kind": "object",
        "fields": [
          {"name":"type","required":true,"schema":{"kind":"string","const":"speed"}},
          {"name":"id","required":true,"schema":{"kind":"integer"}},
          {"name":"factor","required":true,"schema":{"kind":"number","min":0.05,"max":10.0}}
        ]
      },
      "reply": [{"name":"speed","required":true,"schema":{"kind":"number","min":0.05,"max":10.0}}]
    },
    {
      "type": "stop",
      "channel": "command",
      "body": {
        "kind": "object",
        "fields": [
          {"name":"type","required":true,"schema":{"kind":"string","const":"stop"}},
          {"name":"id","required":true,"schema":{"kind":"integer"}}
        ]
      },
      "reply": [{"name":"perception","required":true,"schema":{"kind":"boolean","const":false}}]
    },
    {
      "type": "estop",
      "channel": "command",
      "body": {
        "kind": "object",
        "fields": [
          {"name":"type","required":true,"schema":{"kind":"string","const":"estop"}},
          {"name":"id","required":true,"schema":{"kind":"integer"}}
        ]
      },
      "reply": [{"name":"perception","required":true,"schema":{"kind":"boolean","const":false}}]
    },
    {
      "type": "clear",
      "channel": "command",
      "body": {
        "kind": "object",
        "fields": [
          {"name":"type","required":true,"schema":{"kind":"string","const":"clear"}},
          {"name":"id","required":true,"schema":{"kind":"integer"}}
        ]
      },
      "reply": [{"name":"perception","required":true,"schema":{"kind":"boolean","const":false}}]
    },
    {
      "type": "ping",
      "channel": "command",
      "body": {
        "kind": "object",
        "fields": [
          {"name":"type","required":true,"schema":{"kind":"string","const":"ping"}},
          {"name":"id","required":true,"schema":{"kind":"integer"}}
        ]
      },
      "reply": [{"name":"time","required":true,"schema":{"kind":"number"}}]
    },
    {
      "type": "frame_window",
      "channel": "command",
      "body": {
        "kind": "object",
        "fields": [
          {"name":"type","required":true,"schema":{"kind":"string","const":"frame_window"}},
          {"name":"id","required":true,"schema":{"kind":"integer"}},
          {"name":"frames","required":true,"schema":{"kind":"integer","min":0.0,"max":64.0}}
        ]
      },
      "reply": [
        {"name":"window","required":true,"schema":{"kind":"integer","min":0.0,"max":64.0}},
        {"name":"frames_sent","required":true,"schema":{"kind":"integer","min":0.0}},
        {"name":"frames_acked","required":true,"schema":{"kind":"integer","min":0.0}}
      ]
    },
    {
      "type": "frame_ack",
      "channel": "command",
      "body": {
        "kind": "object",
        "fields": [
          {"name":"type","required":true,"schema":{"kind":"string","const":"frame_ack"}},
          {"name":"id","required":true,"schema":{"kind":"integer"}},
          {"name":"frames","required":true,"schema":{"kind":"integer","min":0.0}}
        ]
      },
      "reply": [
        {"name":"window","required":true,"schema":{"kind":"integer","min":0.0,"max":64.0}},
        {"name":"frames_sent","required":true,"schema":{"kind":"integer","min":0.0}},
        {"name":"frames_acked","required":true,"schema":{"kind":"integer","min":0.0}}
      ]
    },
    {
      "type": "hello",
      "channel": "text",
      "body": {
        "kind": "object",
        "fields": [
          {"name":"type","required":true,"schema":{"kind":"string","const":"hello"}},
          {"name":"protocol","required":true,"schema":{"kind":"string","const":"saccade-gui"}},
          {"name":"version","required":true,"schema":{"kind":"integer","const":2}},
          {"name":"client","required":true,"schema":{"kind":"integer","min":1.0}},
          {"name":"mode","required":true,"schema":{"kind":"string","values":["demo","gui"]}}
        ]
      }
    },
    {
      "type": "state",
      "channel": "text",
      "body": {
        "kind": "object",
        "fields": [
          {"name":"type","required":true,"schema":{"kind":"string","const":"state"}},
          {"name":"step","required":true,"schema":{"kind":"integer","min":0.0}},
          {"name":"time","required":true,"schema":{"kind":"number"}},
          {"name":"paused","required":true,"schema":{"kind":"boolean"}},
          {"name":"speed","required":true,"schema":{"kind":"number","min":0.05,"max":10.0}},
          {"name":"perception","required":true,"schema":{"kind":"boolean"}},
          {"name":"manual","required":true,"schema":{"kind":"boolean"}},
          {"name":"effects","required":true,"schema":{"ref":"effects","nullable":true}},
          {
            "name": "joints",
            "required": true,
            "schema": {
              "kind": "object",
              "nullable": true,
              "fields": [
                {"name":"positions","required":true,"schema":{"ref":"joints"}},
                {"name":"targets","required":true,"schema":{"ref":"joints"}},
                {"name":"velocities","required":true,"schema":{"ref":"joints"}},
                {"name":"arrived","required":true,"schema":{"kind":"boolean"}}
              ]
            }
          },
          {
            "name": "frames",
            "required": true,
            "schema": {
              "kind": "object",
              "nullable": true,
              "fields": [
                {"name":"X_WB","required":true,"schema":{"ref":"pose"}},
                {"name":"X_WC","required":true,"schema":{"ref":"pose"}},
                {"name":"links","required":true,"schema":{"kind":"object","fields":[],"open":true}},
                {"name":"left","required":true,"schema":{"ref":"pose"}},
                {"name":"right","required":true,"schema":{"ref":"pose"}}
              ]
            }
          },
          {"name":"fixation_W","required":true,"schema":{"ref":"point","nullable":true}},
          {
            "name": "target",
            "required": true,
            "schema": {
              "kind": "object",
              "nullable": true,
              "fields": [
                {"name":"valid","required":true,"schema":{"kind":"boolean","const":true}},
                {"name":"p_W","required":true,"schema":{"ref":"point"}},
                {"name":"id","required":true,"schema":{"kind":"integer"}}
              ]
            }
          },
          {
            "name": "fixation_error_deg",
            "required": true,
            "schema": {
              "kind": "object",
              "nullable": true,
              "fields": [
                {"name":"left","required":true,"schema":{"kind":"number","min":0.0}},
                {"name":"right","required":true,"schema":{"kind":"number","min":0.0}}
              ]
            }
          },
          {
            "name": "objects",
            "required": true,
            "schema": {
              "kind": "array",
              "items": [
                {
                  "kind": "object",
                  "fields": [
                    {"name":"name","required":true,"schema":{"kind":"string"}},
                    {"name":"X_WO","required":true,"schema":{"ref":"pose"}}
                  ]
                }
              ]
            }
          },
          {
            "name": "timing",
            "required": true,
            "schema": {
              "kind": "object",
              "fields": [
                {"name":"step_ms","required":true,"schema":{"kind":"number","min":0.0}},
                {"name":"steps_per_s","required":true,"schema":{"kind":"number","min":0.0}},
                {"name":"realtime_factor","required":true,"schema":{"kind":"number","min":0.0}},
                {"name":"frames_per_s","required":true,"schema":{"kind":"number","min":0.0}}
              ]
            }
          },
          {
            "name": "head_status",
            "required": true,
            "schema": {"kind":"object","nullable":true,"fields":[],"open":true}
          },
          {
            "name": "recording",
            "required": true,
            "schema": {
              "kind": "object",
              "nullable": true,
              "fields": [
                {"name":"file","required":true,"schema":{"kind":"string"}},
                {"name":"megabytes","required":true,"schema":{"kind":"number","min":0.0}}
              ]
            }
          }
        ]
      }
    },
    {
      "type": "map",
      "channel": "text",
      "body": {
        "kind": "object",
        "fields": [
          {"name":"type","required":true,"schema":{"kind":"string","const":"map"}},
          {"name":"time","required":true,"schema":{"kind":"number"}},
          {"name":"frame","required":true,"schema":{"kind":"integer"}},
          {"name":"resolution_m","required":true,"schema":{"kind":"number","min":0.0}},
          {"name":"fused","required":true,"schema":{"kind":"integer","min":0.0}},
          {"name":"total","required":true,"schema":{"kind":"integer","min":0.0}},
          {"name":"points","required":true,"schema":{"kind":"array","items":[{"kind":"number"}]}},
          {
            "name": "inhibited",
            "required": true,
            "schema": {
              "kind": "array",
              "items": [
                {
                  "kind": "object",
                  "fields": [
                    {"name":"p_W","required":true,"schema":{"ref":"point"}},
                    {"name":"radius_m","required":true,"schema":{"kind":"number","min":0.0}},
                    {
                      "name": "strength",
                      "required": true,
                      "schema": {"kind":"number","min":0.0,"max":1.0}
                    }
                  ]
                }
              ]
            }
          }
        ]
      }
    },
    {
      "type": "reply",
      "channel": "text",
      "body": {
        "kind": "object",
        "fields": [
          {"name":"type","required":true,"schema":{"kind":"string","const":"reply"}},
          {"name":"id","required":true,"schema":{"kind":"integer"}},
          {"name":"ok","required":true,"schema":{"kind":"boolean","const":true}}
        ]
      }
    },
    {
      "type": "error",
      "channel": "text",
      "body": {
        "kind": "object",
        "fields": [
          {"name":"type","required":true,"schema":{"kind":"string","const":"error"}},
          {"name":"id","required":true,"schema":{"kind":"integer","nullable":true}},
          {"name":"error","required":true,"schema":{"kind":"string"}}
        ]
      }
    },
    {
      "type": "event",
      "channel": "text",
      "body": {
        "kind": "object",
        "fields": [
          {"name":"type","required":true,"schema":{"kind":"string","const":"event"}},
          {
            "name": "level",
            "required": true,
            "schema": {"kind":"string","values":["info","warning","error"]}
          },
          {"name":"message","required":true,"schema":{"kind":"string"}}
        ]
      }
    },
    {
      "type": "frame",
      "channel": "frame",
      "body": {
        "kind": "object",
        "fields": [
          {"name":"type","required":true,"schema":{"kind":"string","const":"frame"}},
          {"name":"camera","required":true,"schema":{"kind":"string"}},
          {"name":"frame","required":true,"schema":{"kind":"integer"}},
          {"name":"time","required":true,"schema":{"kind":"number"}},
          {"name":"width","required":true,"schema":{"kind":"integer","min":1.0}},
          {"name":"height","required":true,"schema":{"kind":"integer","min":1.0}},
          {"name":"overlay","required":true,"schema":{"kind":"boolean"}},
          {"name":"exposure_s","required":true,"schema":{"kind":"number","min":0.0}},
          {"name":"gain_db","required":true,"schema":{"kind":"number"}},
          {"name":"focus_m","required":true,"schema":{"kind":"number","min":0.0}}
        ]
      }
    },
    {
      "type": "scene",
      "channel": "document",
      "body": {
        "kind": "object",
        "fields": [
          {"name":"protocol","required":true,"schema":{"kind":"string","const":"saccade-gui"}},
          {"name":"version","required":true,"schema":{"kind":"integer","const":2}},
          {"name":"mode","required":true,"schema":{"kind":"string","values":["demo","gui"]}},
          {"name":"name","required":true,"schema":{"kind":"string"}},
          {"name":"time","required":true,"schema":{"kind":"number"}},
          {"name":"background","required":true,"schema":{"ref":"rgb"}},
          {
            "name": "ground",
            "required": true,
            "schema": {
              "kind": "object",
              "fields": [
                {"name":"enabled","required":true,"schema":{"kind":"boolean"}},
                {"name":"size","required":true,"schema":{"kind":"number","min":0.0}},
                {
                  "name": "pattern",
                  "required": true,
                  "schema": {"kind":"string","values":["plain","grid","checker"]}
                },
                {"name":"cell","required":true,"schema":{"kind":"number","min":0.0}},
                {"name":"line_width","required":true,"schema":{"kind":"number","min":0.0}},
                {"name":"color","required":true,"schema":{"ref":"rgb"}},
                {"name":"color2","required":true,"schema":{"ref":"rgb"}}
              ]
            }
          },
          {
            "name": "lights",
            "required": true,
            "schema": {
              "kind": "array",
              "items": [
                {
                  "kind": "object",
                  "fields": [
                    {
                      "name": "type",
                      "required": true,
                      "schema": {"kind":"string","values":["ambient","directional","point"]}
                    },
                    {"name":"color","required":true,"schema":{"ref":"rgb"}},
                    {"name":"intensity","required":true,"schema":{"kind":"number","min":0.0}},
                    {"name":"direction","required":true,"schema":{"ref":"point"}},
                    {"name":"position","required":true,"schema":{"ref":"point"}},
                    {"name":"attenuation","required":true,"schema":{"kind":"number","min":0.0}}
                  ]
                }
              ]
            }
          },
          {
            "name": "models",
            "required": true,
            "schema": {
              "kind": "array",
              "items": [
                {
                  "kind": "object",
                  "fields": [
                    {"name":"source","required":true,"schema":{"kind":"string"}},
                    {"name":"url","required":true,"schema":{"kind":"string"}},
                    {
                      "name": "bounds",
                      "required": true,
                      "schema": {"kind":"array","items":[{"ref":"point"},{"ref":"point"}],"length":2}
                    },
                    {
                      "name": "materials",
                      "required": true,
                      "schema": {
                        "kind": "array",
                        "items": [
                          {
                            "kind": "object",
                            "fields": [
                              {"name":"base_color","required":true,"schema":{"ref":"rgba"}},
                              {
                                "name": "texture",
                                "required": true,
                                "schema": {"kind":"string","nullable":true}
                              },
                              {"name":"specular","required":true,"schema":{"kind":"number"}},
                              {"name":"shininess","required":true,"schema":{"kind":"number"}}
                            ]
                          }
                        ]
                      }
                    },
                    {
                      "name": "meshes",
                      "required": true,
                      "schema": {
                        "kind": "array",
                        "items": [
                          {
                            "kind": "object",
                            "fields": [
                              {
                                "name": "vertices",
                                "required": true,
                                "schema": {"kind":"integer","min":0.0}
                              },
                              {
                                "name": "indices",
                                "required": true,
                                "schema": {"kind":"integer","min":0.0}
                              },
                              {"name":"uvs","required":true,"schema":{"kind":"boolean"}},
                              {
                                "name": "material",
                                "required": true,
                                "schema": {"kind":"integer","min":0.0}
                              }
                            ]
                          }
                        ]
                      }
                    }
                  ]
                }
              ]
            }
          },
          {
            "name": "objects",
            "required": true,
            "schema": {
              "kind": "array",
              "items": [
                {
                  "kind": "object",
                  "fields": [
                    {"name":"name","required":true,"schema":{"kind":"string"}},
                    {"name":"id","required":true,"schema":{"kind":"integer"}},
                    {"name":"model","required":true,"schema":{"kind":"integer","min":-1.0}},
                    {"name":"scale","required":true,"schema":{"ref":"point"}},
                    {"name":"X_WO","required":true,"schema":{"ref":"pose"}},
                    {"name":"moving","required":true,"schema":{"kind":"boolean"}}
                  ]
                }
              ]
            }
          },
          {
            "name": "robot",
            "required": true,
            "schema": {
              "kind": "object",
              "nullable": true,
              "fields": [
                {"name":"visible","required":true,"schema":{"kind":"boolean"}},
                {
                  "name": "links",
                  "required": true,
                  "schema": {
                    "kind": "array",
                    "items": [
                      {
                        "kind": "object",
                        "fields": [
                          {"name":"name","required":true,"schema":{"kind":"string"}},
                          {
                            "name": "parent",
                            "required": true,
                            "schema": {"kind":"string","nullable":true}
                          },
                          {
                            "name": "joint",
                            "required": true,
                            "schema": {"kind":"string","nullable":true}
                          }
                        ]
                      }
                    ]
                  }
                },
                {
                  "name": "parts",
                  "required": true,
                  "schema": {
                    "kind": "array",
                    "items": [
                      {
                        "kind": "object",
                        "fields": [
                          {"name":"link","required":true,"schema":{"kind":"string"}},
                          {"name":"model","required":true,"schema":{"kind":"integer","min":-1.0}},
                          {"name":"X_LinkPart","required":true,"schema":{"ref":"pose"}},
                          {"name":"scale","required":true,"schema":{"ref":"point"}}
                        ]
                      }
                    ]
                  }
                }
              ]
            }
          },
          {
            "name": "head",
            "required": true,
            "schema": {
              "kind": "object",
              "fields": [
                {"name":"name","required":true,"schema":{"kind":"string"}},
                {
                  "name": "joints",
                  "required": true,
                  "schema": {
                    "kind": "array",
                    "items": [
                      {
                        "kind": "object",
                        "fields": [
                          {"name":"name","required":true,"schema":{"kind":"string"}},
                          {
                            "name": "type",
                            "required": true,
                            "schema": {"kind":"string","values":["revolute","continuous","prismatic"]}
                          },
                          {"name":"link","required":true,"schema":{"kind":"string"}},
                          {"name":"axis","required":true,"schema":{"ref":"point"}},
                          {"name":"min","required":true,"schema":{"kind":"number","nullable":true}},
                          {"name":"max","required":true,"schema":{"kind":"number","nullable":true}},
                          {
                            "name": "max_velocity",
                            "required": true,
                            "schema": {"kind":"number","min":0.0}
                          },
                          {"name":"driven","required":true,"schema":{"kind":"boolean"}}
                        ]
                      }
                    ]
                  }
                },
                {
                  "name": "symmetric",
                  "required": true,
                  "schema": {
                    "kind": "array",
                    "items": [
                      {
                        "kind": "array",
                        "items": [{"kind":"string"},{"kind":"string"},{"kind":"number"}],
                        "length": 3
                      }
                    ]
                  }
                }
              ]
            }
          },
          {
            "name": "cameras",
            "required": true,
            "schema": {
              "kind": "array",
              "items": [
                {
                  "kind": "object",
                  "fields": [
                    {"name":"width","required":true,"schema":{"kind":"integer","min":1.0}},
                    {"name":"height","required":true,"schema":{"kind":"integer","min":1.0}},
                    {
                      "name": "K",
                      "required": true,
                      "schema": {
                        "kind": "array",
                        "items": [{"kind":"array","items":[{"kind":"number"}],"length":3}],
                        "length": 3
                      }
                    },
                    {
                      "name": "distortion",
                      "required": true,
                      "schema": {
                        "kind": "object",
                        "fields": [
                          {
                            "name": "model",
                            "required": true,
                            "schema": {"kind":"string","values":["none","radtan","fisheye"]}
                          },
                          {
                            "name": "coefficients",
                            "required": true,
                            "schema": {"kind":"array","items":[{"kind":"number"}]}
                          }
                        ]
                      }
                    },
                    {"name":"name","required":true,"schema":{"kind":"string"}},
                    {
                      "name": "eye",
                      "required": true,
                      "schema": {"kind":"string","values":["left","right","world"]}
                    },
                    {"name":"X_WC","required":true,"schema":{"ref":"pose"}},
                    {"name":"near","required":true,"schema":{"kind":"number","min":0.0}},
                    {"name":"far","required":true,"schema":{"kind":"number","min":0.0}},
                    {"name":"optics","required":true,"schema":{"kind":"boolean"}},
                    {"name":"color","required":true,"schema":{"kind":"boolean"}}
                  ]
                }
              ]
            }
          },
          {
            "name": "commands",
            "required": true,
            "schema": {
              "kind": "object",
              "fields": [
                {"name":"effects","required":true,"schema":{"kind":"boolean"}},
                {"name":"perception","required":true,"schema":{"kind":"boolean"}},
                {"name":"estop","required":true,"schema":{"kind":"boolean"}}
              ]
            }
          }
        ]
      }
    }
  ]
};

export const kProtocol = table.protocol;
export const kVersion = table.version;

/**
 * The first problem of a message, '' when there is none; each names the message and the field
 * ("state: field 'joints.positions.pan' must be a number, got string").
 * checkServerMessage(message, command): a WebSocket text message of the server; a reply is
 * checked against the reply of `command` (the type of the command it answers) when given.
 * checkFrameHeader(header), checkSceneDocument(scene), checkCommand(command).
 */
export const { checkServerMessage, checkFrameHeader, checkSceneDocument, checkCommand } =
  makeChecks(table);

/** A server's text message: checkServerMessage. */
export const validate = checkServerMessage;
