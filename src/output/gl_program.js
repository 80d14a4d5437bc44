    var prog = gl.createProgram();
    gl.attachShader(prog, shader(gl, gl.VERTEX_SHADER,
      "attribute vec3 p; attribute vec3 n; attribute vec3 c;" +
      "uniform mat3 r; uniform vec2 s; varying vec3 vn; varying vec3 vc;" +
      "void main() { vec3 q = r * p; vn = r * n; vc = c;" +
      " gl_Position = vec4(q.x * s.x, q.y * s.y, -0.5 * q.z, 1.0); }"));
    gl.attachShader(prog, shader(gl, gl.FRAGMENT_SHADER,
      "precision mediump float; varying vec3 vn; varying vec3 vc;" +
      "void main() { vec3 l = normalize(vec3(-0.3, 0.4, 0.866));" +
      " float d = length(vn) > 0.0 ? abs(dot(normalize(vn), l)) : 1.0;" +
      " gl_FragColor = vec4(vc * (0.35 + 0.65 * d), 1.0); }"));
    gl.linkProgram(prog);
    if (!gl.getProgramParameter(prog, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(prog));
    gl.useProgram(prog);
    var loc = { p: gl.getAttribLocation(prog, "p"), n: gl.getAttribLocation(prog, "n"),
      c: gl.getAttribLocation(prog, "c"), r: gl.getUniformLocation(prog, "r"),
      s: gl.getUniformLocation(prog, "s") };
